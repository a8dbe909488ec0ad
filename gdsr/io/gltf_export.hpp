// glTF 2.0 export of an animated garment: one mesh with UVs whose per-frame shapes are morph
// targets, played by one weights animation (a DCC tool such as Blender imports the targets
// as shape keys; three.js plays them as morph targets). Written as NAME.gltf (JSON) next to
// NAME.bin (little-endian buffer). Y up, metres, as in gdsr.
//
// glTF vertices carry one UV each, so the mesh has one vertex per UV vertex of the garment
// (seam vertices appear once per pattern piece): vertex i sits at V[uv_to_vertex[i]].
// The base shape is frame 0; target k (k = 1..T-1) holds frame k minus frame 0, and the
// animation sets weight 1 on target k at time k / fps (linear interpolation between frames).
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <string>
#include <vector>

namespace gdsr {

struct GltfOptions {
  double fps = 30;               // frames per second of the animation
  std::string name = "garment";  // mesh / node name
  Points2 texcoord;              // per UV vertex x 2, glTF convention (0,0 = image top-left);
                                 // empty: the UV layout's bounding box mapped to [0,1]^2, v flipped
  std::vector<float> rgba = {0.75f, 0.78f, 0.85f, 1.0f};  // base colour of the double-sided material
};

// Writes gltf_path (must end in ".gltf") and the buffer beside it (".bin" in place of
// ".gltf"), each atomically. frames: T >= 1 frames of mesh.V.rows() x 3 positions.
// Throws gdsr::Error on an empty sequence, a frame of another vertex count, a non-finite
// position or an I/O failure.
void write_gltf_sequence(const std::string& gltf_path, const GarmentMesh& mesh, const std::vector<Points3>& frames,
                         const GltfOptions& opt = {});

// The texcoords of opt.texcoord's default: UV bounding box to [0,1]^2 (aspect kept, v flipped).
Points2 normalized_texcoords(const Points2& UV);

}  // namespace gdsr

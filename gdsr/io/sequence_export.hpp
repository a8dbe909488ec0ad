// One animated garment written in the formats DCC tools open (docs/exports.md):
//   NAME.gltf + NAME.bin   glTF 2.0, morph-target animation (gltf_export.hpp)
//   NAME.pc2 + NAME_rest.obj   point cache on a rest OBJ for Blender's Mesh Cache modifier
//   obj/NAME_FFFFF.obj     one OBJ (v, vt, f) per exported frame, FFFFF the frame number
// Y up, metres.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace gdsr {

struct SequenceExportOptions {
  bool gltf = true, pc2 = true, obj = true;
  int obj_every = 1;    // OBJ for every k-th frame
  int first_frame = 0;  // frame number of frames[0] (OBJ names)
  double fps = 30;      // frames per second (glTF animation)
  Points2 texcoord;     // glTF texcoords per UV vertex (GltfOptions::texcoord); empty: normalised UV
};

// Writes the files of `name` into dir (created if missing) and returns what it wrote:
// {"name", "vertices", "uv_vertices", "faces", "frames", "gltf", "pc2", "rest_obj", "obj": [...]}
// with paths relative to dir (absent keys for formats not written). Throws gdsr::Error on
// bad input (see write_gltf_sequence / write_pc2) or an I/O failure.
nlohmann::json export_sequence(const std::string& dir, const std::string& name, const GarmentMesh& mesh,
                               const std::vector<Points3>& frames, const SequenceExportOptions& opt = {});

}  // namespace gdsr

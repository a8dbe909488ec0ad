// Triangle meshes: the one geometry type shared by the body, the garments, the simulator
// and the model. Positions in metres, one row per vertex; faces are vertex indices,
// counter-clockwise seen from the outside (the normal side).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // Vec3::cross
#include <string>
#include <vector>

namespace gdsr {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;
using Points3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  // N x 3, metres
using Points2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;  // N x 2 (UV, metres)
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;       // F x 3 indices

struct TriMesh {
  Points3 V;  // vertices x 3, metres
  Faces F;    // triangles x 3
  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_faces() const { return static_cast<int>(F.rows()); }
};

// A garment mesh in two parametrisations: 3-D positions with seams welded (V, F) and the
// flat sewing pattern (UV, FUV) where seam vertices have several copies. Face f is the
// same triangle in both: F.row(f) indexes V, FUV.row(f) indexes UV. uv_to_vertex maps a
// UV copy to its welded 3-D vertex.
struct GarmentMesh {
  Points3 V;                      // welded vertices x 3, metres
  Faces F;                        // triangles x 3, into V
  Points2 UV;                     // UV vertices x 2, metres on the flat pattern
  Faces FUV;                      // triangles x 3, into UV
  std::vector<int> uv_to_vertex;  // UV vertex -> welded vertex
  std::vector<int> layer;         // welded vertex -> cloth layer (0 = innermost); may be empty
  int num_layers() const;
};

}  // namespace gdsr

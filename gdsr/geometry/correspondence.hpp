// LR <-> HR correspondences of one garment, computed in the shared UV layout (both meshes
// come from the same sewing pattern, so their flat patterns overlap).
//
//   hr_from_lr: each HR welded vertex -> (LR triangle, barycentric), "10 from 30". A welded
//               HR vertex with several UV copies uses its lowest-index UV copy.
//   lr_from_hr: each LR *UV* vertex -> (HR triangle, barycentric), "30 from 10". An LR
//               welded vertex is the average over its UV copies (seams).
//   hr_nearest_lr: each HR welded vertex -> the LR welded vertex nearest in UV (same UV copy
//               as hr_from_lr; among the LR UV vertices).
// UV points outside every triangle use the nearest triangle with clamped barycentrics.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <vector>

namespace gdsr {

using Bary = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  // N x 3 weights

struct BaryMap {
  std::vector<int> tri;  // one triangle per sample point
  Bary bary;             // samples x 3
  int size() const { return static_cast<int>(tri.size()); }
};

struct Correspondence {
  BaryMap hr_from_lr;                // HR vertices; triangles of lr_F
  BaryMap lr_from_hr;                // LR UV vertices; triangles of hr_F
  std::vector<int> hr_nearest_lr;    // HR vertices -> LR vertex
  Faces lr_F, hr_F;                  // welded faces of both meshes
  std::vector<int> lr_uv_to_vertex;  // LR UV vertex -> LR welded vertex
  int lr_vertices = 0, hr_vertices = 0;
};

// Throws if either layout is empty or every UV triangle is degenerate.
Correspondence compute_correspondence(const GarmentMesh& lr, const GarmentMesh& hr);

// Samples `positions` (rows indexed by the vertices of `faces`) at each map entry.
Points3 apply_bary(const BaryMap& map, const Faces& faces, const Points3& positions);

// LR positions (lr_vertices x 3, metres) -> HR positions (hr_vertices x 3).
Points3 upsample(const Correspondence& c, const Points3& lr_positions);
// HR positions (hr_vertices x 3) -> LR positions (lr_vertices x 3), seam copies averaged.
Points3 downsample(const Correspondence& c, const Points3& hr_positions);
// S = upsample(downsample(hr)), hr_vertices x 3: an HR shape at the LR scale, what the LR mesh can
// hold of it (a perfect coarse correction reaches S; HR - S are the wrinkles left to the detail).
Points3 at_lr_scale(const Correspondence& c, const Points3& hr_positions);

// The first (lowest-index) UV copy of each welded vertex; throws if a vertex has none.
std::vector<int> first_uv_copy(const std::vector<int>& uv_to_vertex, int num_vertices);

// Checks that the correspondence indices fit the meshes; throws naming the problem.
void validate_correspondence(const Correspondence& c);

}  // namespace gdsr

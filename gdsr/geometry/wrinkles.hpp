// Wrinkle measures of a triangle mesh: the mean dihedral angle over interior edges, and the
// mean absolute mean curvature sum_e(theta_e |e|) / (2 area), which unlike the dihedral angle
// does not shrink with the edge length, so LR and HR meshes (or HR and LR upsampled to HR
// topology) can be compared directly. Used by the simulator's metrics and by the dataset
// validity figures (gdsr/data/validity.hpp).
#pragma once

#include "gdsr/geometry/mesh.hpp"

namespace gdsr {

struct WrinkleMeasure {
  double mean_dihedral = 0;   // radians, over interior edges (edges with exactly two faces)
  double mean_curvature = 0;  // 1/m (1/unit of X): sum(theta_e |e|) / (2 area)
};

// X: vertices x 3 (metres), F: faces x 3.
WrinkleMeasure wrinkle_measure(const Points3& X, const Faces& F);

}  // namespace gdsr

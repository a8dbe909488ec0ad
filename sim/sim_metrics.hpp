// Quality numbers of a simulated garment frame (metres, seconds, kg): the paper's
// stretch/shear energies from the UV deformation gradient (appendix B: E_u = (|w_u| - 1)^2,
// E_v = (|w_v| - 1)^2, E_uv = (w_u . w_v)^2, means over triangles), body penetration,
// kinetic energy, and wrinkle measures (mean dihedral angle; mean absolute mean curvature,
// which unlike the dihedral angle does not shrink with the edge length, so LR and HR can
// be compared directly).
#pragma once

#include "gdsr/mesh.hpp"

#include <vector>

namespace sim {

struct StrainEnergies {
  double E_u = 0, E_v = 0, E_uv = 0;  // means over triangles (dimensionless)
};
// X: garment positions (welded vertices x 3) using g.F / g.FUV / g.UV.
StrainEnergies strain_energies(const gdsr::GarmentMesh& g, const gdsr::Points3& X);

struct Penetration {
  double max_depth = 0;   // metres below the body surface (0 if none)
  double mean_depth = 0;  // metres, mean over all garment vertices
  int count = 0;          // vertices inside the body
};
// Signed distance of each garment vertex to the body (searched within `radius` metres).
Penetration body_penetration(const gdsr::Points3& X, const gdsr::Faces& body_F, const gdsr::Points3& body_V,
                             double radius = 0.05);

// 0.5 sum m |v|^2 in joules, v = (X1 - X0) / dt; mass = density (kg/m^2) x UV area share.
double kinetic_energy(const gdsr::GarmentMesh& g, const gdsr::Points3& X0, const gdsr::Points3& X1, double dt,
                      double density = 0.08);

struct WrinkleMeasure {
  double mean_dihedral = 0;   // radians, over interior edges
  double mean_curvature = 0;  // 1/m: sum(theta_e |e|) / (2 area)
};
WrinkleMeasure wrinkle_measure(const gdsr::Points3& X, const gdsr::Faces& F);

// Positions of `to`'s welded vertices sampled from `from_X` (positions of `from`) through
// the shared UV layout: each UV vertex of `to` takes the barycentric point of the `from` UV
// triangle containing it (nearest triangle, clamped, outside every triangle); seam copies
// are averaged. Used to compare HR with the LR upsampled to HR topology (same pattern).
gdsr::Points3 resample_by_uv(const gdsr::GarmentMesh& from, const gdsr::Points3& from_X, const gdsr::GarmentMesh& to);

struct FrameMetrics {
  StrainEnergies strain;
  Penetration penetration;
  double kinetic_energy = 0;  // joules (0 for the first frame)
  WrinkleMeasure wrinkles;
};
// Per-frame metrics of a simulated sequence (frames[t] garment positions; body_frames[t]
// body poses of body_F, may be empty to skip penetration).
std::vector<FrameMetrics> sequence_metrics(const gdsr::GarmentMesh& g, const std::vector<gdsr::Points3>& frames,
                                           const gdsr::Faces& body_F, const std::vector<gdsr::Points3>& body_frames,
                                           double fps, double density = 0.08);

}  // namespace sim

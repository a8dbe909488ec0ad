// Quality numbers of a simulated garment frame (metres, seconds, kg): the paper's
// stretch/shear energies (gdsr/geometry/strain.hpp), body penetration,
// kinetic energy, and wrinkle measures (mean dihedral angle; mean absolute mean curvature,
// which unlike the dihedral angle does not shrink with the edge length, so LR and HR can
// be compared directly).
#pragma once

#include "gdsr/geometry/mesh.hpp"
#include "gdsr/geometry/strain.hpp"
#include "gdsr/geometry/wrinkles.hpp"

#include <vector>

namespace sim {

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

// Wrinkle measures live in gdsr/geometry/wrinkles.hpp (shared with the dataset validity figures).
using gdsr::wrinkle_measure;
using gdsr::WrinkleMeasure;

// Positions of `to`'s welded vertices sampled from `from_X` (positions of `from`) through
// the shared UV layout: each UV vertex of `to` takes the barycentric point of the `from` UV
// triangle containing it (nearest triangle, clamped, outside every triangle); seam copies
// are averaged. Used to compare HR with the LR upsampled to HR topology (same pattern).
gdsr::Points3 resample_by_uv(const gdsr::GarmentMesh& from, const gdsr::Points3& from_X, const gdsr::GarmentMesh& to);

struct FrameMetrics {
  gdsr::StrainEnergies strain;  // gdsr/geometry/strain.hpp
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

// Small garments for the loss / patch / collision tests (header-only, test helpers).
#pragma once

#include "gdsr/geometry/mesh.hpp"
#include "tests/support/grid_garment.hpp"

#include <cmath>
#include <vector>

namespace gdsr_test {

// The grid's positions with a smooth bump (amplitude a) and a small deterministic in-plane
// jitter, so no dihedral angle is exactly 0 and no L1 difference sits on its kink.
inline gdsr::Points3 bumpy(const gdsr::Points3& V, double a, double scale, int seed = 0) {
  gdsr::Points3 X = V;
  const double L = V.col(0).maxCoeff() + 1e-12;
  for (int r = 0; r < X.rows(); ++r) {
    const double x = V(r, 0) / L, y = V(r, 1) / L;
    X(r, 2) = a * L * (std::sin(2.3 * x + 0.4 + seed) * std::cos(1.7 * y - 0.2) + 0.3 * x * y);
    X(r, 0) += 0.05 * L * std::sin(7.1 * r + seed) / std::sqrt(static_cast<double>(V.rows()));
    X(r, 1) += 0.05 * L * std::cos(5.3 * r + 2 * seed) / std::sqrt(static_cast<double>(V.rows()));
  }
  return X * scale;
}

// A grid garment cut to the triangle x + y < 0.75 L (so the raster has a diagonal edge and a
// large empty region). Unused grid vertices stay (isolated).
inline gdsr::GarmentMesh cut_garment(int n, double h) {
  gdsr::GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec::spaced(n, h));
  const double L = (n - 1) * h;
  std::vector<int> keep;
  for (int f = 0; f < g.F.rows(); ++f) {
    const gdsr::Vec3 c = (g.V.row(g.F(f, 0)) + g.V.row(g.F(f, 1)) + g.V.row(g.F(f, 2))).transpose() / 3.0;
    if (c.x() + c.y() < 0.75 * L) keep.push_back(f);
  }
  gdsr::Faces F(static_cast<int>(keep.size()), 3);
  for (size_t i = 0; i < keep.size(); ++i) F.row(static_cast<int>(i)) = g.F.row(keep[i]);
  g.F = F;
  g.FUV = F;
  return g;
}

}  // namespace gdsr_test

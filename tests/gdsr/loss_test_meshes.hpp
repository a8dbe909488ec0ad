// Small garments for the loss / patch / collision tests (header-only, test helpers).
#pragma once

#include "gdsr/mesh.hpp"

#include <cmath>
#include <vector>

namespace gdsr_test {

// n x n vertex grid with spacing h in the plane z = 0, UV = (x, y); every square split by
// the diagonal (i, j)-(i+1, j+1); counter-clockwise seen from +z (normal +z).
inline gdsr::GarmentMesh grid_garment(int n, double h) {
  gdsr::GarmentMesh g;
  g.V.resize(n * n, 3);
  g.UV.resize(n * n, 2);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      g.V.row(j * n + i) << i * h, j * h, 0.0;
      g.UV.row(j * n + i) << i * h, j * h;
    }
  g.F.resize(2 * (n - 1) * (n - 1), 3);
  int f = 0;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
      g.F.row(f++) << a, b, c;
      g.F.row(f++) << a, c, d;
    }
  g.FUV = g.F;
  g.uv_to_vertex.resize(n * n);
  for (int i = 0; i < n * n; ++i) g.uv_to_vertex[i] = i;
  return g;
}

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
  gdsr::GarmentMesh g = gdsr_test::grid_garment(n, h);
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

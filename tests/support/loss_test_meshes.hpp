// Small garments for the loss / patch / collision tests (header-only, test helpers).
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "tests/support/grid_garment.hpp"

#include <algorithm>
#include <cmath>
#include <string>
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

// P with vertex a moved onto the midpoint of edge (b, c) and lifted by h (metres) across the
// edge, in the plane of the edge and the z axis: triangle (a, b, c) becomes a sliver of height h.
inline gdsr::Points3 sliver(const gdsr::Points3& P, int a, int b, int c, double h) {
  gdsr::Points3 Q = P;
  const Eigen::RowVector3d e = (P.row(c) - P.row(b)).normalized();
  const Eigen::RowVector3d up = e.cross(Eigen::RowVector3d(0, 0, 1)).normalized().cross(e);
  Q.row(a) = 0.5 * (P.row(b) + P.row(c)) + h * up;
  return Q;
}

// The degenerate versions of triangle (a, b, c) of P a predicted mesh can contain: a 1e-9 m
// sliver, zero area (a on edge b c), coincident vertices (c = b), collapsed to a point.
struct DegenerateCase {
  std::string name;
  gdsr::Points3 P;
};
inline std::vector<DegenerateCase> degenerate_cases(const gdsr::Points3& P, int a, int b, int c) {
  std::vector<DegenerateCase> out{{"sliver of 1e-9 m", sliver(P, a, b, c, 1e-9)},
                                  {"zero area", sliver(P, a, b, c, 0.0)}};
  gdsr::Points3 Q = P;
  Q.row(c) = Q.row(b);
  out.push_back({"coincident vertices", Q});
  Q.row(a) = Q.row(b);
  out.push_back({"collapsed to a point", Q});
  return out;
}

// |dL/dx_v| per vertex of a flat [V x 3] gradient.
inline std::vector<double> vertex_norms(const ag::Storage<double>& grad) {
  std::vector<double> n(grad.size() / 3);
  for (size_t i = 0; i < n.size(); ++i)
    n[i] = std::sqrt(grad[3 * i] * grad[3 * i] + grad[3 * i + 1] * grad[3 * i + 1] + grad[3 * i + 2] * grad[3 * i + 2]);
  return n;
}

inline double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace gdsr_test

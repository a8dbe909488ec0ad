#include "gdsr/geometry/strain.hpp"

#include "gdsr/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace gdsr {

namespace {

void check_positions(const GarmentMesh& g, const Points3& X) {
  if (X.rows() != g.V.rows())
    gdsr::fail("strain",
               std::to_string(X.rows()) + " positions for a garment of " + std::to_string(g.V.rows()) + " vertices");
}

// The UV triangle of face f is degenerate (|det Dm| <= 1e-8 x longest UV edge^2, scale-free).
bool degenerate_uv(const GarmentMesh& g, int f, Eigen::Matrix2d& Dm) {
  const Vec2 u0 = g.UV.row(g.FUV(f, 0)), u1 = g.UV.row(g.FUV(f, 1)), u2 = g.UV.row(g.FUV(f, 2));
  Dm.col(0) = u1 - u0;
  Dm.col(1) = u2 - u0;
  const double scale2 = std::max({Dm.col(0).squaredNorm(), Dm.col(1).squaredNorm(), (u2 - u1).squaredNorm()});
  return !(std::abs(Dm.determinant()) > 1e-8 * scale2);
}

}  // namespace

StrainEnergies strain_energies(const GarmentMesh& g, const Points3& X) {
  check_positions(g, X);
  StrainEnergies s;
  int n = 0;
  for (int f = 0; f < g.F.rows(); ++f) {
    Eigen::Matrix2d Dm;
    if (degenerate_uv(g, f, Dm)) continue;
    Eigen::Matrix<double, 3, 2> Ds;
    Ds.col(0) = X.row(g.F(f, 1)) - X.row(g.F(f, 0));
    Ds.col(1) = X.row(g.F(f, 2)) - X.row(g.F(f, 0));
    const Eigen::Matrix<double, 3, 2> w = Ds * Dm.inverse();
    const double lu = w.col(0).norm(), lv = w.col(1).norm(), d = w.col(0).dot(w.col(1));
    s.E_u += (lu - 1) * (lu - 1);
    s.E_v += (lv - 1) * (lv - 1);
    s.E_uv += d * d;
    s.E_u_stretched += lu > 1 ? (lu - 1) * (lu - 1) : 0.0;
    s.E_v_stretched += lv > 1 ? (lv - 1) * (lv - 1) : 0.0;
    ++n;
  }
  if (n > 0) {
    s.E_u /= n;
    s.E_v /= n;
    s.E_uv /= n;
    s.E_u_stretched /= n;
    s.E_v_stretched /= n;
  }
  return s;
}

namespace {
// Calls fn(i, j, length / pattern length) for each edge (i, j) of g's triangles that
// strain_energies does not leave out (an edge shared by two triangles, twice).
template <class Fn> void for_each_edge_stretch(const GarmentMesh& g, const Points3& X, Fn&& fn) {
  check_positions(g, X);
  for (int f = 0; f < g.F.rows(); ++f) {
    Eigen::Matrix2d Dm;
    if (degenerate_uv(g, f, Dm)) continue;
    for (int k = 0; k < 3; ++k) {
      const int a = (k + 1) % 3;
      const double rest = (g.UV.row(g.FUV(f, k)) - g.UV.row(g.FUV(f, a))).norm();  // > 0: not degenerate
      fn(g.F(f, k), g.F(f, a), (X.row(g.F(f, k)) - X.row(g.F(f, a))).norm() / rest);
    }
  }
}
}  // namespace

double max_edge_stretch(const GarmentMesh& g, const Points3& X) {
  double worst = 0;
  for_each_edge_stretch(g, X, [&](int, int, double r) { worst = std::max(worst, r); });
  // std::max drops a NaN ratio; a non-finite position must not read as intact cloth.
  return X.allFinite() ? worst : std::numeric_limits<double>::quiet_NaN();
}

std::vector<int> overstretched_vertices(const GarmentMesh& g, const Points3& X, double limit) {
  std::vector<int> out;
  for_each_edge_stretch(g, X, [&](int i, int j, double r) {
    if (!(r <= limit)) out.insert(out.end(), {i, j});  // a NaN counts as torn
  });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace gdsr

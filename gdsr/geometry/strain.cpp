#include "gdsr/geometry/strain.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

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

// Face f's deformation gradient from UV to 3-D (3 x 2); false for a degenerate UV triangle.
bool deformation_gradient(const GarmentMesh& g, const Points3& X, int f, Eigen::Matrix<double, 3, 2>& w) {
  Eigen::Matrix2d Dm;
  if (degenerate_uv(g, f, Dm)) return false;
  Eigen::Matrix<double, 3, 2> Ds;
  Ds.col(0) = X.row(g.F(f, 1)) - X.row(g.F(f, 0));
  Ds.col(1) = X.row(g.F(f, 2)) - X.row(g.F(f, 0));
  w = Ds * Dm.inverse();
  return true;
}

// Adds face f's energies to s (sums, not yet means); false for a degenerate UV triangle.
bool add_face(const GarmentMesh& g, const Points3& X, int f, StrainEnergies& s) {
  Eigen::Matrix<double, 3, 2> w;
  if (!deformation_gradient(g, X, f, w)) return false;
  const double lu = w.col(0).norm(), lv = w.col(1).norm(), d = w.col(0).dot(w.col(1));
  s.E_u += (lu - 1) * (lu - 1);
  s.E_v += (lv - 1) * (lv - 1);
  s.E_uv += d * d;
  s.E_u_stretched += lu > 1 ? (lu - 1) * (lu - 1) : 0.0;
  s.E_v_stretched += lv > 1 ? (lv - 1) * (lv - 1) : 0.0;
  ++s.faces;
  return true;
}

void to_means(StrainEnergies& s) {
  if (s.faces == 0) return;
  for (double* e : {&s.E_u, &s.E_v, &s.E_uv, &s.E_u_stretched, &s.E_v_stretched}) *e /= s.faces;
}

}  // namespace

StrainEnergies strain_energies(const GarmentMesh& g, const Points3& X) {
  check_positions(g, X);
  StrainEnergies s;
  for (int f = 0; f < g.F.rows(); ++f) add_face(g, X, f, s);
  to_means(s);
  return s;
}

std::vector<Vec2> fibre_stretch(const GarmentMesh& g, const Points3& X) {
  check_positions(g, X);
  std::vector<Vec2> out(g.F.rows(), Vec2::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (int f = 0; f < g.F.rows(); ++f) {
    Eigen::Matrix<double, 3, 2> w;
    if (deformation_gradient(g, X, f, w)) out[f] = Vec2(w.col(0).norm(), w.col(1).norm());
  }
  return out;
}

std::vector<int> pattern_pieces(const GarmentMesh& g) {
  const std::vector<int> island = uv_islands(g);
  std::vector<int> piece(g.FUV.rows());
  for (int f = 0; f < g.FUV.rows(); ++f) piece[f] = island[g.FUV(f, 0)];
  return piece;
}

std::vector<StrainEnergies> strain_energies_by_piece(const GarmentMesh& g, const Points3& X,
                                                     const std::vector<int>& piece) {
  check_positions(g, X);
  if (piece.size() != static_cast<size_t>(g.F.rows()))
    gdsr::fail("strain", std::to_string(piece.size()) + " piece indices for " + std::to_string(g.F.rows()) + " faces");
  const int n = piece.empty() ? 0 : 1 + *std::max_element(piece.begin(), piece.end());
  std::vector<StrainEnergies> s(n);
  for (int f = 0; f < g.F.rows(); ++f) {
    if (piece[f] < 0) gdsr::fail("strain", "negative piece index for face " + std::to_string(f));
    add_face(g, X, f, s[piece[f]]);
  }
  for (auto& e : s) to_means(e);
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

#include "gdsr/geometry/strain.hpp"

#include "gdsr/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gdsr {

StrainEnergies strain_energies(const GarmentMesh& g, const Points3& X) {
  if (X.rows() != g.V.rows())
    gdsr::fail("strain",
               std::to_string(X.rows()) + " positions for a garment of " + std::to_string(g.V.rows()) + " vertices");
  StrainEnergies s;
  int n = 0;
  for (int f = 0; f < g.F.rows(); ++f) {
    const Vec2 u0 = g.UV.row(g.FUV(f, 0)), u1 = g.UV.row(g.FUV(f, 1)), u2 = g.UV.row(g.FUV(f, 2));
    Eigen::Matrix2d Dm;
    Dm.col(0) = u1 - u0;
    Dm.col(1) = u2 - u0;
    const double scale2 = std::max({Dm.col(0).squaredNorm(), Dm.col(1).squaredNorm(), (u2 - u1).squaredNorm()});
    if (!(std::abs(Dm.determinant()) > 1e-8 * scale2)) continue;
    Eigen::Matrix<double, 3, 2> Ds;
    Ds.col(0) = X.row(g.F(f, 1)) - X.row(g.F(f, 0));
    Ds.col(1) = X.row(g.F(f, 2)) - X.row(g.F(f, 0));
    const Eigen::Matrix<double, 3, 2> w = Ds * Dm.inverse();
    const double lu = w.col(0).norm(), lv = w.col(1).norm(), d = w.col(0).dot(w.col(1));
    s.E_u += (lu - 1) * (lu - 1);
    s.E_v += (lv - 1) * (lv - 1);
    s.E_uv += d * d;
    ++n;
  }
  if (n > 0) {
    s.E_u /= n;
    s.E_v /= n;
    s.E_uv /= n;
  }
  return s;
}

}  // namespace gdsr

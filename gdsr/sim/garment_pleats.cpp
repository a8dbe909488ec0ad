// Pleated short skirt: the pleats are folded into the rest placement. The skirt is a
// general cone (apex on the body axis above the waist) over a wavy base curve, radius
// r(y) (1 + q sin(N psi)) at height y and angle psi around the axis: a cone over any curve
// is developable, so the flat pattern (front and back panels) is its exact development and
// the placement is isometric but for the waistband, which follows the pleats and, drawn in
// to the waist section, is gathered and pinned.
#include "gdsr/sim/garment_design.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace sim {

using gdsr::Vec2;
using gdsr::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct PleatedCone {
  double k = 0.5, q = 0.1, apex_y = 0;  // horizontal radius per metre below the apex; wave depth
  int N = 12;                           // pleats around the body (a multiple of 4: side seams at wave nodes)
  std::vector<double> psi, phi;         // development table: angle around the axis -> flat angle
  // Unscaled generator direction at psi: (k m sin psi, -1, k m cos psi), m = 1 + q sin(N psi).
  Vec3 dir(double p) const {
    const double m = 1 + q * std::sin(N * p);
    return Vec3(k * m * std::sin(p), -1, k * m * std::cos(p));
  }
  void develop() {
    const int M = 48 * N * 16;
    psi.resize(M + 1);
    phi.resize(M + 1);
    Vec3 prev = dir(-kPi / 2).normalized();
    psi[0] = -kPi / 2;
    phi[0] = 0;
    for (int i = 1; i <= M; ++i) {
      psi[i] = -kPi / 2 + 2 * kPi * i / M;
      const Vec3 cur = dir(psi[i]).normalized();
      phi[i] = phi[i - 1] + 2 * std::asin(std::min(1.0, 0.5 * (cur - prev).norm()));  // arc on the unit sphere
      prev = cur;
    }
  }
  double phi_of(double p) const {  // p in [-pi/2, 3pi/2]
    const double t = (p + kPi / 2) / (2 * kPi) * (psi.size() - 1);
    const int i = std::clamp(static_cast<int>(t), 0, static_cast<int>(psi.size()) - 2);
    return phi[i] + (t - i) * (phi[i + 1] - phi[i]);
  }
  double psi_of(double f) const {
    const int i = std::clamp(static_cast<int>(std::upper_bound(phi.begin(), phi.end(), f) - phi.begin()) - 1, 0,
                             static_cast<int>(phi.size()) - 2);
    return psi[i] + (f - phi[i]) / (phi[i + 1] - phi[i]) * (psi[i + 1] - psi[i]);
  }
};

}  // namespace

GarmentDesign design_skirt_pleated(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  auto c = std::make_shared<PleatedCone>();
  const double ease = 0.015 * s, length = 0.40 * s;
  // Waist radius such that the pleats' inner folds clear the waist; slope such that they clear the hips.
  const double Rw = (lm.waist_r + ease) / (1 - c->q);
  const double drop = std::max(lm.waist_y - lm.hip_y, 0.02);
  // (twice the ease at the hips: a rounded pelvis bulges outside the straight cone line)
  c->k = std::max(0.45, ((lm.hip_r + 2 * ease) / (1 - c->q) - Rw) / drop);
  c->apex_y = lm.waist_y + Rw / c->k;
  c->develop();
  const double waist_y = lm.waist_y, hem_y = lm.waist_y - length;
  const Vec3 axis = lm.axis;
  // Flat panels: polar coordinates (rho = distance from the apex, flat angle) around each
  // panel's apex; the panel's middle generator points down.
  GarmentDesign d;
  const int per_panel = c->N / 2 * 4;  // outline points per pleat: 4
  Vec2 apex[2];
  double phi_mid[2];
  auto waist = std::make_shared<std::vector<std::vector<Vec2>>>(2);
  double x_off = 0;
  for (int k = 0; k < 2; ++k) {
    const double p0 = -kPi / 2 + k * kPi, p1 = p0 + kPi;
    phi_mid[k] = 0.5 * (c->phi_of(p0) + c->phi_of(p1));
    const double rho_hem_max = (c->apex_y - hem_y) * c->dir(0).norm() * 1.2;
    apex[k] = Vec2(x_off + rho_hem_max, rho_hem_max + 0.01);
    auto flat = [&](double p, double y) {
      const double rho = (c->apex_y - y) * c->dir(p).norm();
      const double a = -kPi / 2 + (c->phi_of(p) - phi_mid[k]);
      return Vec2(apex[k] + rho * Vec2(std::cos(a), std::sin(a)));
    };
    std::vector<Vec2> o;
    for (int i = 0; i <= per_panel; ++i) o.push_back(flat(p0 + kPi * i / per_panel, hem_y));
    for (int i = per_panel; i >= 0; --i) o.push_back(flat(p0 + kPi * i / per_panel, waist_y));
    (*waist)[k].assign(o.begin() + per_panel + 1, o.end());
    double xmax = x_off;
    for (const auto& v : o) xmax = std::max(xmax, v.x());
    x_off = xmax + 0.05;
    d.pattern.panels.push_back({k == 0 ? "pleated_front" : "pleated_back", o});
  }
  // Edge per_panel: +psi side (hem -> waist); last edge: -psi side (waist -> hem).
  const int e_plus = per_panel, e_minus = 2 * per_panel + 1;
  d.pattern.seams.push_back({0, e_plus, 1, e_minus, true});
  d.pattern.seams.push_back({1, e_plus, 0, e_minus, true});
  const Vec2 ap0 = apex[0], ap1 = apex[1];
  const double pm0 = phi_mid[0], pm1 = phi_mid[1];
  auto height = [c, ap0, ap1, pm0, pm1](int panel, const Vec2& uv, double& p) {
    const Vec2 r = uv - (panel == 0 ? ap0 : ap1);
    const double f = std::atan2(r.y(), r.x()) + kPi / 2 + (panel == 0 ? pm0 : pm1);
    p = c->psi_of(f);
    return c->apex_y - r.norm() / c->dir(p).norm();
  };
  // The waistband follows the waist section, as for the cone skirts (place_cone in
  // garment_cone.hpp says why).
  auto fit = std::make_shared<const BodyLandmarks>(lm);
  d.place = [c, axis, height, fit, waist_y](int panel, const Vec2& uv) {
    double p;
    const double y = height(panel, uv, p);
    Vec3 g = c->dir(p) * (c->apex_y - y);
    const double r = std::hypot(g.x(), g.z());
    if (r > 0) {
      const double shrink = waist_fit_shrink(*fit, std::atan2(g.x(), g.z()), waist_y - y);
      g.x() *= (r - shrink) / r;
      g.z() *= (r - shrink) / r;
    }
    return Vec3(axis.x() + g.x(), y, axis.z() + g.z());
  };
  d.pinned = [waist](int panel, const Vec2& uv) {  // on the waist edges of the outline
    const auto& w = (*waist)[panel];
    for (size_t i = 0; i + 1 < w.size(); ++i) {
      const Vec2 e = w[i + 1] - w[i];
      const double t = std::clamp((uv - w[i]).dot(e) / e.squaredNorm(), 0.0, 1.0);
      if ((w[i] + t * e - uv).norm() < 1e-9) return true;
    }
    return false;
  };
  return d;
}

}  // namespace sim

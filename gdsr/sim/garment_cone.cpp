#include "gdsr/sim/garment_cone.hpp"

#include <algorithm>
#include <cmath>

namespace sim {

using gdsr::Vec2;
using gdsr::Vec3;

namespace {
constexpr double kPi = 3.14159265358979323846;
}

Cone::Cone(double a_, double b_, double L_) : a(a_), b(b_), L(L_) {
  Ls = std::hypot(L, b - a);
  sin_a = (b - a) / Ls;
  cos_a = L / Ls;
  R1 = a / sin_a;
  theta = 2 * kPi * sin_a;
}

SkirtLayout add_cone_skirt(Pattern& p, const Cone& c, double x_offset, const std::string& name, int n_inner,
                           const Scallops& hem, int n_outer) {
  const double R2 = c.R1 + c.Ls;
  const double half = c.theta / 4;  // each panel spans theta / 2
  const double hem_step = hem.depth > 0 ? std::min(0.03, hem.length / 8) : 0.03;
  if (n_outer <= 0) n_outer = std::max(8, static_cast<int>(std::ceil(R2 * 2 * half / hem_step)));
  if (n_inner <= 0) n_inner = std::max(4, static_cast<int>(std::ceil(c.R1 * 2 * half / 0.03)));
  const double width = 2 * R2 * std::sin(std::min(half, kPi / 2)) + 0.05;
  SkirtLayout lay{c, {}, n_outer, n_inner};
  const int base = static_cast<int>(p.panels.size());
  for (int k = 0; k < 2; ++k) {
    const Vec2 apex(x_offset + width / 2 + k * (width + 0.05), R2 + 0.01);
    lay.apex[k] = apex;
    const double mid = -kPi / 2;
    auto outl = arc_points(apex, R2, mid - half, mid + half, n_outer);
    if (hem.depth > 0) {  // scallops: whole number of them along the hem, points on the arc between
      const double arc = R2 * 2 * half;
      const double n_sc = std::max(1.0, std::round(arc / hem.length));
      for (int j = 0; j <= n_outer; ++j) {
        const double t = static_cast<double>(j) / n_outer;
        const double r = R2 - hem.depth * (1 - std::abs(std::sin(kPi * n_sc * t)));
        outl[j] = apex + r * Vec2(std::cos(mid - half + 2 * half * t), std::sin(mid - half + 2 * half * t));
      }
    }
    const auto in = arc_points(apex, c.R1, mid + half, mid - half, n_inner);
    outl.insert(outl.end(), in.begin(), in.end());
    p.panels.push_back({name + (k == 0 ? "_front" : "_back"), outl});
  }
  const int e_plus = n_outer, e_minus = n_outer + n_inner + 1;
  p.seams.push_back({base, e_plus, base + 1, e_minus, true});
  p.seams.push_back({base + 1, e_plus, base, e_minus, true});
  return lay;
}

Vec3 place_cone(const SkirtLayout& s, int k, const Vec2& uv, const Vec3& axis, double waist_y,
                const WaistCurve* waist) {
  const Vec2 d = uv - s.apex[k];
  const double rho = d.norm();
  const double phi = std::atan2(d.y(), d.x()) + kPi / 2;  // 0 at the panel centre
  double psi = phi / s.cone.sin_a + (k == 0 ? 0.0 : kPi);
  const double apex_y = waist_y + s.cone.R1 * s.cone.cos_a;
  double r = rho * s.cone.sin_a;
  if (waist) {
    const double w = waist->weight((rho - s.cone.R1) * s.cone.cos_a);
    if (w > 0) {
      const double psi_lin = psi;
      double shift = waist->psi_at(psi_lin / (2 * kPi)) - psi_lin;  // the same fraction of the way round
      shift -= 2 * kPi * std::round(shift / (2 * kPi));
      psi = psi_lin + w * shift;
      r += w * (waist->radius(psi) - s.cone.a);
    }
  }
  return Vec3(axis.x() + r * std::sin(psi), apex_y - rho * s.cone.cos_a, axis.z() + r * std::cos(psi));
}

Cone skirt_cone(const BodyLandmarks& lm, double length, double min_flare, double ease) {
  const double a = waist_perimeter(lm, ease) / (2 * kPi);
  const double drop = std::max(lm.waist_y - lm.hip_y, 0.02);
  const double need = a + (lm.hip_r + 2 * ease - a) * length / drop;
  return Cone(a, std::max({need, a + min_flare, a + 0.02}), length);
}

double pattern_max_x(const Pattern& p) {
  double x = 0;
  for (const auto& pan : p.panels)
    for (const auto& v : pan.outline) x = std::max(x, v.x());
  return x;
}

void finish_cone_design(GarmentDesign& d, std::shared_ptr<const std::vector<SkirtLayout>> lays, const BodyLandmarks& lm,
                        bool layered) {
  const Vec3 axis = lm.axis;
  const double waist_y = lm.waist_y;
  auto waists = std::make_shared<std::vector<WaistCurve>>();
  for (const SkirtLayout& L : *lays) waists->emplace_back(lm, L.cone.a);
  d.place = [lays, axis, waist_y, waists](int panel, const Vec2& uv) {
    return place_cone((*lays)[panel / 2], panel % 2, uv, axis, waist_y, &(*waists)[panel / 2]);
  };
  d.pinned = [lays](int panel, const Vec2& uv) {
    const SkirtLayout& L = (*lays)[panel / 2];
    return (uv - L.apex[panel % 2]).norm() < L.cone.R1 + 1e-9;
  };
  if (layered) d.layer = [](int panel) { return panel / 2; };
}

}  // namespace sim

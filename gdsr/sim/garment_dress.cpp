// Double-layered strapless dress: each layer is a bodice (a cylinder from under the armpits
// to the waist, front and back panels) sewn at the waist to a flared cone skirt (front and
// back panels). Layer 0 is the fitted inner dress, layer 1 a looser, shorter outer layer
// 12 mm further out that flares more. The top band of both layers is pinned (elastic band).
#include "gdsr/sim/garment_cone.hpp"
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

struct DressLayer {
  SkirtLayout skirt{Cone(0.1, 0.2, 0.1), {}, 0, 0};
  double R = 0, Hb = 0;   // bodice radius, height (metres)
  Vec2 bodice_origin[2];  // flat position of each bodice panel's bottom centre
};

// Panels: inner skirt front/back, outer skirt front/back, inner bodice front/back, outer bodice front/back.
int layer_of(int panel) { return (panel < 4 ? panel : panel - 4) / 2; }

}  // namespace

GarmentDesign design_dress_layered(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  const double top_y = lm.armpit_y - 0.02 * s;
  const double drop = std::max(lm.waist_y - lm.hip_y, 0.02);
  GarmentDesign d;
  Pattern& p = d.pattern;
  auto layers = std::make_shared<std::vector<DressLayer>>(2);
  double slope = 0;
  for (int l = 0; l < 2; ++l) {
    DressLayer& L = (*layers)[l];
    L.R = lm.bust_r + (0.015 + 0.012 * l) * s;
    L.Hb = top_y - lm.waist_y;
    const double length = (l == 0 ? 0.55 : 0.48) * s;
    const double need = (lm.hip_r + 0.02 * s - L.R) / drop;  // clear the hips
    slope = std::max({need, l == 0 ? 0.15 : slope + 0.3, slope + 0.02});
    // Spread legs: the hem clears each leg's line (plus 6 cm for the leg) at the hem height.
    const double hem_y = lm.waist_y - length;
    for (int j = 0; j < 2; ++j) {
      const Vec3 dl = lm.leg_bottom[j] - lm.leg_top[j];
      const Vec3 at = lm.leg_top[j] + dl * ((hem_y - lm.leg_top[j].y()) / (dl.y() < -1e-6 ? dl.y() : -1.0));
      slope = std::max(slope, (std::hypot(at.x() - lm.axis.x(), at.z() - lm.axis.z()) + 0.06 * s - L.R) / length);
    }
    const Cone c(L.R, L.R + slope * length, length);
    const int n = std::max(8, static_cast<int>(std::ceil(kPi * L.R / (0.03 * s))));
    L.skirt = add_cone_skirt(p, c, l == 0 ? 0.0 : pattern_max_x(p) + 0.1, l == 0 ? "inner_skirt" : "outer_skirt", n);
  }
  // Bodices in a row above the skirts; bottom edge split like the skirt's waist arc.
  double y0 = 0;
  for (const auto& pan : p.panels)
    for (const auto& v : pan.outline) y0 = std::max(y0, v.y() + 0.1);
  double x0 = 0;
  for (int l = 0; l < 2; ++l) {
    DressLayer& L = (*layers)[l];
    const double W = kPi * L.R;
    const int n = L.skirt.n_inner;
    for (int k = 0; k < 2; ++k) {
      L.bodice_origin[k] = Vec2(x0 + W / 2, y0);
      x0 += W + 0.05;
      std::vector<Vec2> o;
      for (int i = 0; i <= n; ++i) o.push_back(L.bodice_origin[k] + Vec2(-W / 2 + W * i / n, 0));
      o.push_back(L.bodice_origin[k] + Vec2(W / 2, L.Hb));
      o.push_back(L.bodice_origin[k] + Vec2(-W / 2, L.Hb));
      p.panels.push_back({std::string(l == 0 ? "inner" : "outer") + (k == 0 ? "_bodice_front" : "_bodice_back"), o});
    }
    const int sf = 2 * l, bf = 4 + 2 * l;  // panels: skirts (inner, outer), then bodices
    // Side seams of the bodice (edge n: right side going up, n + 2: left side going down).
    p.seams.push_back({bf, n, bf + 1, n + 2, true});
    p.seams.push_back({bf + 1, n, bf, n + 2, true});
    // Waist seams: bodice bottom edge i (psi increasing) meets skirt waist edge n-1-i.
    for (int k = 0; k < 2; ++k)
      for (int i = 0; i < n; ++i) p.seams.push_back({bf + k, i, sf + k, L.skirt.n_outer + 1 + (n - 1 - i), true});
  }
  const Vec3 axis = lm.axis;
  const double waist_y = lm.waist_y;
  d.place = [layers, axis, waist_y](int panel, const Vec2& uv) {
    const DressLayer& L = (*layers)[layer_of(panel)];
    const int k = panel % 2;
    if (panel < 4) return place_cone(L.skirt, k, uv, axis, waist_y);
    const Vec2 q = uv - L.bodice_origin[k];
    const double psi = q.x() / L.R + k * kPi;
    return Vec3(axis.x() + L.R * std::sin(psi), waist_y + q.y(), axis.z() + L.R * std::cos(psi));
  };
  d.pinned = [layers](int panel, const Vec2& uv) {  // the bodices' top band
    const DressLayer& L = (*layers)[layer_of(panel)];
    return panel >= 4 && uv.y() - L.bodice_origin[panel % 2].y() > L.Hb - 1e-9;
  };
  d.layer = layer_of;
  return d;
}

}  // namespace sim

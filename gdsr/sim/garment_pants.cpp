// Long pants: front and back leg panels like the shorts (garment_tubes.cpp), with legs down
// to the ankles that taper to a hem of ~15 cm diameter. Each leg tube follows the body's leg
// from the crotch to the ankle (spread legs tilt it), so the legs clear the body; above the
// crotch the tubes blend into the hip cylinder. Above the hips a yoke, a cone frustum like a
// short skirt's (garment_cone.hpp), narrows from the hip cylinder to the waist section, which
// its waistband follows at its pattern length; it is sewn to the legs along the hip line.
// Side seams, inseams, a short crotch seam between the legs and the hip seam; the waistband
// is pinned.
#include "gdsr/sim/garment_cone.hpp"
#include "gdsr/sim/garment_design.hpp"
#include "gdsr/sim/garment_legs.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace sim {

using gdsr::Vec2;
using gdsr::Vec3;

namespace {
constexpr double kPi = 3.14159265358979323846;
}

GarmentDesign design_pants(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  const Vec3 axis = lm.axis;
  GarmentDesign d;
  Pattern& p = d.pattern;
  const double R = lm.hip_r + 0.03 * s;
  const double W = kPi * R;
  const double hem_y = lm.ankle_y + 0.015 * s;
  const double Htot = lm.waist_y - hem_y;
  // Relaxed fit, the crotch 6 cm below the body's: with 3 cm the 30 mm mesh folded through
  // itself in the crotch more often on CMU 01_01 (59% of frames clean against 63%; 9 cm gave
  // 78%, but its leg tubes were placed 5 mm inside the thighs).
  const double Hc = lm.crotch_y - 0.06 * s - hem_y;
  const double r_hem = 0.075 * s;
  const double g = std::max(0.02 * s, W / 2 - kPi * r_hem), blend = 0.10 * s;
  // A curved crotch seam between the legs (radius c, garment_legs.hpp): with the notch ending
  // in one vertex (c = 0) that vertex gathered 673 degrees of pattern angle, and the HR edges
  // around it tore past 2x when salsa legs spread (3.4x on 61_03).
  const double c = 0.03 * s;
  // The hip line: at the hips, but above the legs' blend into the hip cylinder.
  const double Ht = std::min(std::max(lm.hip_y - hem_y, Hc + blend), Htot - 0.04 * s);
  const double ease = 0.015 * s;
  const double a = waist_perimeter(lm, ease) / (2 * kPi);
  const Cone yoke(a, std::max(R, a + 0.01 * s), Htot - Ht);
  // Leg panels up to the hip line, whose edge is split like the yoke's lower arc (n edges from top_edge).
  const int n = std::max(8, static_cast<int>(std::ceil(kPi * yoke.b / 0.03)));
  const int top_edge = add_two_leg_panels(p, W, Ht, Hc, g, "pants", n, c);
  // The yoke (panels 2, 3): its lower arc's edge j (psi increasing) meets hip-line edge n - 1 - j.
  auto lay = std::make_shared<SkirtLayout>(add_cone_skirt(p, yoke, pattern_max_x(p) + 0.1, "pants_yoke", 0, {}, n));
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < n; ++j) p.seams.push_back({2 + k, j, k, top_edge + (n - 1 - j), true});
  // Its waist fit fades out over the whole yoke, so that its lower arc is the hip circle.
  auto waist = std::make_shared<const WaistCurve>(lm, a, yoke.L);
  // Each leg tube is a tilted cone around the body leg's line (from `top` at the crotch
  // height, R/2 to the side, to the leg's centre near the ankle); below the top quarter its
  // cross-sections are perpendicular to that line (e1 outwards, e2 forwards), so the
  // placement stays isometric there.
  Vec3 top[2], dir[2], e1[2], e2[2];
  for (int k = 0; k < 2; ++k) {
    const double side = k == 0 ? 1.0 : -1.0;
    // The crotch arc takes 2c from each leg's girth at the crotch: its tube, c / pi thinner
    // there, is moved out by as much, so that its outer side still meets the hip cylinder
    // (placed 5 mm inside the thighs of CMU 01_01 otherwise).
    top[k] = Vec3(side * (R / 2 + c / kPi), hem_y + Hc, 0);
    const Vec3 dl = lm.leg_bottom[k] - lm.leg_top[k];
    Vec3 bot = lm.leg_top[k] + dl * ((hem_y - lm.leg_top[k].y()) / (dl.y() < -1e-6 ? dl.y() : -1.0)) - axis;
    bot.y() = hem_y;
    bot.x() = side * std::max(side * bot.x(), r_hem + 0.01 * s);  // keep the tubes apart
    dir[k] = (bot - top[k]).normalized();                         // downwards along the leg
    e1[k] = (side * Vec3::UnitX() - dir[k] * (side * dir[k].x())).normalized();
    e2[k] = (Vec3::UnitZ() - dir[k] * dir[k].z() - e1[k] * e1[k].z()).normalized();
  }
  const double waist_y = lm.waist_y;
  d.place = [=](int panel, const Vec2& uv) {
    if (panel >= 2) return place_cone(*lay, panel - 2, uv, axis, waist_y, waist.get());
    const LegCoords lc = leg_coords(panel, uv, W, R, hem_y, Hc, g, blend, c);
    if (lc.on_hip) return Vec3(axis + lc.hip);
    const double y = uv.y();
    // Cross-sections horizontal at the crotch (the tubes' inseams 4c / pi apart there),
    // turning perpendicular to the leg line within the top quarter of the leg.
    const double w = std::clamp((Hc - y) / (0.25 * Hc), 0.0, 1.0);
    auto tube = [&](int k, double t) {  // k: 3-D side of the leg
      const double side = k == 0 ? 1.0 : -1.0;
      const Vec3 centre = top[k] + dir[k] * std::max(0.0, Hc - y);  // at the crotch height above it
      const Vec3 f1 = ((1 - w) * side * Vec3::UnitX() + w * e1[k]).normalized();
      const Vec3 f2 = ((1 - w) * Vec3::UnitZ() + w * e2[k]).normalized();
      return Vec3(centre + lc.r * std::cos(kPi * t) * f1 + lc.zs * lc.r * std::sin(kPi * t) * f2);
    };
    // The cloth over the crotch arc spans the gap between the two legs' inseams (the arc's
    // pattern length, pi c, placed on 4c / pi: the settle eases it in).
    const Vec3 leg =
        lc.across > 0 ? Vec3((1 - lc.across) * tube(lc.leg, 1) + lc.across * tube(1 - lc.leg, 1)) : tube(lc.leg, lc.t);
    return Vec3(axis + (1 - lc.blend) * leg + lc.blend * lc.hip);
  };
  d.pinned = [lay](int panel, const Vec2& uv) {  // the yoke's waistband
    return panel >= 2 && (uv - lay->apex[panel - 2]).norm() < lay->cone.R1 + 1e-9;
  };
  return d;
}

}  // namespace sim

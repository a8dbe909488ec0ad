// Two-panel tube garments: a sleeveless top and shorts.
#include "gdsr/sim/garment_design.hpp"
#include "gdsr/sim/garment_legs.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace sim {

using gdsr::Vec2;
using gdsr::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- Two-panel tube garments (top, shorts) ---------------------------------------------
// Front panel centred at x = 0 maps its flat x to the angle psi = x / R around the axis;
// the back panel continues the same sense of rotation (psi = pi + x / R), so both face out.

Panel mirror_copy(const Panel& pan, double dx, const std::string& name) {
  Panel q{name, pan.outline};
  for (auto& v : q.outline) v.x() += dx;
  return q;
}

}  // namespace

GarmentDesign design_top(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  const Vec3 axis = lm.axis;
  GarmentDesign d;
  Pattern& p = d.pattern;
  const double R = lm.chest_r + 0.035 * s;
  const double W = kPi * R;
  const double hem_y = lm.waist_y - 0.06 * s;
  const double Hs = lm.armpit_y - 0.02 * s - hem_y;             // side seam height
  const double psi_s = std::asin(std::min(0.9, 0.11 * s / R));  // strap centre angle
  const double xs = R * psi_s, sw = 0.035 * s;                  // strap centre, half width (flat)
  const double Hsh = lm.shoulder_y + 0.02 * s - hem_y;          // shoulder line height
  const double Htop = Hsh + R * std::cos(psi_s);                // plus the fold over the shoulder
  const double Hneck = Hsh - 0.10 * s;
  std::vector<Vec2> o{Vec2(-W / 2, 0), Vec2(W / 2, 0), Vec2(W / 2, Hs)};
  // Right armhole (quarter ellipse) up to the strap's outer edge.
  const int na = 8;
  for (int k = 1; k <= na; ++k) {
    const double t = kPi / 2 * k / na;
    o.push_back(Vec2(xs + sw + (W / 2 - xs - sw) * std::cos(t), Hs + (Htop - Hs) * std::sin(t)));
  }
  o.push_back(Vec2(xs - sw, Htop));  // shoulder seam (right)
  const int nn = 10;                 // neckline (half ellipse, down to Hneck)
  for (int k = 1; k < nn; ++k) {
    const double t = kPi * k / nn;
    o.push_back(Vec2((xs - sw) * std::cos(t), Htop - (Htop - Hneck) * std::sin(t)));
  }
  o.push_back(Vec2(-(xs - sw), Htop));
  o.push_back(Vec2(-(xs + sw), Htop));  // shoulder seam (left)
  for (int k = na - 1; k >= 0; --k) {
    const double t = kPi / 2 * k / na;
    o.push_back(Vec2(-(xs + sw) - (W / 2 - xs - sw) * std::cos(t), Hs + (Htop - Hs) * std::sin(t)));
  }
  const int n = static_cast<int>(o.size());  // last edge: (-W/2, Hs) -> (-W/2, 0)
  Panel front{"top_front", o};
  p.panels.push_back(front);
  p.panels.push_back(mirror_copy(front, W + 0.1, "top_back"));
  const int e_side_r = 1, e_side_l = n - 1;
  const int e_sh_r = 2 + na, e_sh_l = 2 + na + nn + 1;
  p.seams.push_back({0, e_side_r, 1, e_side_l, true});
  p.seams.push_back({1, e_side_r, 0, e_side_l, true});
  p.seams.push_back({0, e_sh_r, 1, e_sh_l, true});
  p.seams.push_back({1, e_sh_r, 0, e_sh_l, true});
  const double E = R * std::cos(psi_s);
  d.place = [=](int panel, const Vec2& uv) {
    const double x = uv.x() - panel * (W + 0.1), y = uv.y();
    const double psi = x / R + panel * kPi;
    double X = R * std::sin(psi), Z = R * std::cos(psi), Y = hem_y + y;
    if (y > Hsh) {  // fold over the shoulder towards the side plane z = 0
      const double f = std::min(1.0, (y - Hsh) / E);
      Z *= 1 - f;
      Y = hem_y + Hsh;
    }
    return Vec3(axis.x() + X, Y, axis.z() + Z);
  };
  return d;
}

GarmentDesign design_shorts(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  const Vec3 axis = lm.axis;
  GarmentDesign d;
  Pattern& p = d.pattern;
  const double R = lm.hip_r + 0.03 * s;
  const double W = kPi * R;
  const double hem_y = lm.crotch_y - 0.16 * s;
  const double Htot = lm.waist_y - hem_y;
  const double Hc = lm.crotch_y - 0.03 * s - hem_y;
  const double g = 0.02 * s, blend = 0.10 * s;
  add_two_leg_panels(p, W, Htot, Hc, g, "shorts");
  d.place = [=](int panel, const Vec2& uv) {
    // Between the crotch and crotch + blend the tubes blend into the hip cylinder, so the
    // crotch point sits between the legs.
    const LegCoords c = leg_coords(panel, uv, W, R, hem_y, Hc, g, blend);
    if (c.on_hip) return Vec3(axis + c.hip);
    const double side = c.leg == 0 ? 1.0 : -1.0;  // 3-D x side of this leg
    const Vec3 leg(side * (R / 2 + c.r * std::cos(kPi * c.t)), c.hip.y(), c.zs * c.r * std::sin(kPi * c.t));
    return Vec3(axis + (1 - c.blend) * leg + c.blend * c.hip);
  };
  d.pinned = [Htot](int, const Vec2& uv) { return uv.y() > Htot - 1e-9; };  // waistband
  return d;
}

}  // namespace sim

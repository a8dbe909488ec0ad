// The two-leg garments' shared pattern-to-body coordinates (garment_tubes.cpp shorts,
// garment_pants.cpp pants): front/back panels of width W (flat metres) wrapped on a hip
// cylinder of radius R above the crotch height Hc (flat y from the hem), split into two leg
// tubes below it, blended into the cylinder over `blend` metres above the crotch.
#pragma once

#include "gdsr/geometry/mesh.hpp"
#include "gdsr/sim/pattern.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace sim {

struct LegCoords {
  gdsr::Vec3 hip;    // point on the hip cylinder, relative to the trunk axis
  bool on_hip;       // at or above crotch + blend: hip is the answer
  double t = 0;      // around the leg: side seam 0, front/back 1/2, inseam 1
  double r = 0;      // leg-tube radius at this height
  int leg = 0;       // 0: the body's +x leg, 1: the -x leg
  double zs = 1;     // +1 front panel, -1 back panel
  double blend = 0;  // weight of the hip cylinder (smoothstep over the blend zone)
};

// x, y: point of panel `panel` (0 front, 1 back, laid W + 0.1 apart); hem_y: 3-D height of
// the hem; g: half-width of the crotch gusset at the hem.
inline LegCoords leg_coords(int panel, const gdsr::Vec2& uv, double W, double R, double hem_y, double Hc, double g,
                            double blend) {
  constexpr double kPi = 3.14159265358979323846;
  LegCoords c;
  const double x = uv.x() - panel * (W + 0.1), y = uv.y();
  const double psi = x / R + panel * kPi;
  c.hip = gdsr::Vec3(R * std::sin(psi), hem_y + y, R * std::cos(psi));
  c.on_hip = y >= Hc + blend;
  if (c.on_hip) return c;
  const double gy = g * std::max(0.0, 1 - y / Hc);
  const double wleg = W / 2 - gy;
  c.t = std::clamp((W / 2 - std::abs(x)) / wleg, 0.0, 1.0);
  c.r = wleg / kPi;
  c.leg = (x >= 0) == (panel == 0) ? 0 : 1;
  c.zs = panel == 0 ? 1.0 : -1.0;
  const double u = std::clamp((y - Hc) / blend, 0.0, 1.0);
  c.blend = u * u * (3 - 2 * u);
  return c;
}

// The two panels `prefix`_front and `prefix`_back (laid W + 0.1 apart, as leg_coords
// expects): width W, height Htot, crotch Hc above the hem, gusset half-width g at the hem;
// side seams and inseams. Edges: hem, inseams, hem (0-3), side up (4), top from +x to -x split
// into n_top equal edges (5 .. 4 + n_top, to sew another panel on), side down (5 + n_top).
inline void add_two_leg_panels(Pattern& p, double W, double Htot, double Hc, double g, const std::string& prefix,
                               int n_top = 1) {
  std::vector<gdsr::Vec2> o{gdsr::Vec2(-W / 2, 0), gdsr::Vec2(-g, 0), gdsr::Vec2(0, Hc), gdsr::Vec2(g, 0),
                            gdsr::Vec2(W / 2, 0)};
  for (int i = 0; i < n_top; ++i) o.push_back(gdsr::Vec2(W / 2 - W * i / n_top, Htot));
  o.push_back(gdsr::Vec2(-W / 2, Htot));
  p.panels.push_back({prefix + "_front", o});
  for (auto& v : o) v.x() += W + 0.1;
  p.panels.push_back({prefix + "_back", o});
  p.seams.push_back({0, 4, 1, 5 + n_top, true});  // side seams
  p.seams.push_back({1, 4, 0, 5 + n_top, true});
  p.seams.push_back({0, 1, 1, 2, true});  // inseams
  p.seams.push_back({0, 2, 1, 1, true});
}

}  // namespace sim

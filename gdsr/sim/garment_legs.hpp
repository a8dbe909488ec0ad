// The two-leg garments' shared pattern-to-body coordinates (garment_tubes.cpp shorts,
// garment_pants.cpp pants): front/back panels of width W (flat metres) wrapped on a hip
// cylinder of radius R above the crotch height Hc (flat y from the hem), split into two leg
// tubes below it, blended into the cylinder over `blend` metres above the crotch. For c > 0
// the notch between the legs ends in a half-circle of radius c, its top at the crotch, instead
// of a point: sewn front to back it is a crotch seam between the legs, which shares the
// saddle's excess pattern angle out along its corners (450 degrees at each, where a pointed
// notch gathers ~670 into one vertex).
#pragma once

#include "gdsr/geometry/mesh.hpp"
#include "gdsr/sim/pattern.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace sim {

struct LegCoords {
  gdsr::Vec3 hip;     // point on the hip cylinder, relative to the trunk axis
  bool on_hip;        // at or above crotch + blend: hip is the answer
  double t = 0;       // around the leg: side seam 0, front/back 1/2, inseam 1
  double r = 0;       // leg-tube radius at this height
  int leg = 0;        // 0: the body's +x leg, 1: the -x leg
  double zs = 1;      // +1 front panel, -1 back panel
  double blend = 0;   // weight of the hip cylinder (smoothstep over the blend zone)
  double across = 0;  // over the crotch arc (|x| < c): the other leg's weight, 1/2 at x = 0
};

// x, y: point of panel `panel` (0 front, 1 back, laid W + 0.1 apart); hem_y: 3-D height of
// the hem; g: half-width of the notch between the legs at the hem, c: radius of the
// half-circle it ends in, its top at the crotch (0: a point; metres).
inline LegCoords leg_coords(int panel, const gdsr::Vec2& uv, double W, double R, double hem_y, double Hc, double g,
                            double blend, double c = 0) {
  constexpr double kPi = 3.14159265358979323846;
  LegCoords lc;
  const double x = uv.x() - panel * (W + 0.1), y = uv.y();
  const double psi = x / R + panel * kPi;
  lc.hip = gdsr::Vec3(R * std::sin(psi), hem_y + y, R * std::cos(psi));
  lc.on_hip = y >= Hc + blend;
  if (lc.on_hip) return lc;
  const double gy = c + (g - c) * std::max(0.0, 1 - y / (Hc - c));
  const double wleg = W / 2 - gy;
  lc.t = std::clamp((W / 2 - std::abs(x)) / wleg, 0.0, 1.0);
  lc.r = wleg / kPi;
  if (std::abs(x) < c) lc.across = (c - std::abs(x)) / (2 * c);
  lc.leg = (x >= 0) == (panel == 0) ? 0 : 1;
  lc.zs = panel == 0 ? 1.0 : -1.0;
  const double u = std::clamp((y - Hc) / blend, 0.0, 1.0);
  lc.blend = u * u * (3 - 2 * u);
  return lc;
}

// Segments of the crotch arc's polygon (45 degrees each: 4 edges of 2.4 cm at c = 3 cm).
inline constexpr int kCrotchArcEdges = 4;

// The two panels `prefix`_front and `prefix`_back (laid W + 0.1 apart, as leg_coords
// expects): width W, height Htot, crotch Hc above the hem, notch half-width g at the hem,
// ending in a point (c = 0) or a half-circle of radius c up to (0, Hc); side seams, inseams
// and, for c > 0, the crotch seam. Edges: hem, inseam, [crotch arc: kCrotchArcEdges,] inseam,
// hem, side up, top from +x to -x split into n_top equal edges (to sew another panel on),
// side down. Returns the first top edge.
inline int add_two_leg_panels(Pattern& p, double W, double Htot, double Hc, double g, const std::string& prefix,
                              int n_top = 1, double c = 0) {
  constexpr double kPi = 3.14159265358979323846;
  std::vector<gdsr::Vec2> o{gdsr::Vec2(-W / 2, 0), gdsr::Vec2(-g, 0)};
  if (c > 0) {
    const auto arc = arc_points(gdsr::Vec2(0, Hc - c), c, kPi, 0, kCrotchArcEdges);
    o.insert(o.end(), arc.begin(), arc.end());
  } else {
    o.push_back(gdsr::Vec2(0, Hc));
  }
  o.push_back(gdsr::Vec2(g, 0));
  o.push_back(gdsr::Vec2(W / 2, 0));
  const int inseam2 = static_cast<int>(o.size()) - 3, side_up = inseam2 + 2, top = side_up + 1;
  for (int i = 0; i < n_top; ++i) o.push_back(gdsr::Vec2(W / 2 - W * i / n_top, Htot));
  o.push_back(gdsr::Vec2(-W / 2, Htot));
  p.panels.push_back({prefix + "_front", o});
  for (auto& v : o) v.x() += W + 0.1;
  p.panels.push_back({prefix + "_back", o});
  const int side_down = top + n_top;
  p.seams.push_back({0, side_up, 1, side_down, true});  // side seams
  p.seams.push_back({1, side_up, 0, side_down, true});
  p.seams.push_back({0, 1, 1, inseam2, true});  // inseams
  p.seams.push_back({0, inseam2, 1, 1, true});
  if (c > 0)  // the crotch seam: the front's -x end meets the back's +x end (both on the body's -x leg)
    for (int j = 0; j < kCrotchArcEdges; ++j) p.seams.push_back({0, 2 + j, 1, 2 + kCrotchArcEdges - 1 - j, true});
  return top;
}

}  // namespace sim

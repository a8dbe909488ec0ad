// The two-leg garments' shared pattern-to-body coordinates (garment_tubes.cpp shorts,
// garment_pants.cpp pants): front/back panels of width W (flat metres) wrapped on a hip
// cylinder of radius R above the crotch height Hc (flat y from the hem), split into two leg
// tubes below it, blended into the cylinder over `blend` metres above the crotch.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <algorithm>
#include <cmath>

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

}  // namespace sim

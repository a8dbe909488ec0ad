// Long skirt with three lace tiers: three nested cone skirts sewn into one waistband (each
// pinned along its waistline), the inner one to mid-calf, each further tier shorter,
// wider and a layer further out (layer ids 0, 1, 2), all with scalloped (lace) hems.
#include "gdsr/sim/garment_cone.hpp"
#include "gdsr/sim/garment_design.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace sim {

using gdsr::Vec2;
using gdsr::Vec3;

GarmentDesign design_skirt_tiered(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  const double L0 = std::max(0.3 * s, lm.waist_y - lm.floor - 0.25 * lm.height);  // inner tier to mid-calf
  const double length[3] = {L0, 0.72 * L0, 0.45 * L0};
  const double ease[3] = {0.015 * s, 0.027 * s, 0.039 * s};  // 12 mm between tiers at the waist
  const double flare[3] = {0.18 * s, 0.22 * s, 0.24 * s};
  GarmentDesign d;
  auto lays = std::make_shared<std::vector<SkirtLayout>>();
  double slope = 0, x_offset = 0;
  for (int k = 0; k < 3; ++k) {
    // Each tier flares at least as fast as the one inside it, so the layers never cross.
    Cone c = skirt_cone(lm, length[k], flare[k], ease[k]);
    slope = std::max(slope + 0.02, (c.b - c.a) / c.L);
    // Spread legs: the hem clears each leg's line (plus 6 cm for the leg) at the hem height.
    const double hem_y = lm.waist_y - c.L;
    for (int j = 0; j < 2; ++j) {
      const Vec3 dl = lm.leg_bottom[j] - lm.leg_top[j];
      const Vec3 at = lm.leg_top[j] + dl * ((hem_y - lm.leg_top[j].y()) / (dl.y() < -1e-6 ? dl.y() : -1.0));
      const double need = std::hypot(at.x() - lm.axis.x(), at.z() - lm.axis.z()) + 0.06 * s;
      slope = std::max(slope, (need - c.a) / c.L);
    }
    c = Cone(c.a, c.a + slope * c.L, c.L);
    lays->push_back(
        add_cone_skirt(d.pattern, c, x_offset, "tier" + std::to_string(k), 0, Scallops{0.02 * s, 0.09 * s}));
    x_offset = pattern_max_x(d.pattern) + 0.1;
  }
  finish_cone_design(d, lays, lm, true);
  return d;
}

}  // namespace sim

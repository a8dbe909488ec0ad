// Cone skirts: short, long and two-layered.
#include "gdsr/sim/garment_cone.hpp"
#include "gdsr/sim/garment_design.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace sim {

using gdsr::Vec2;
using gdsr::Vec3;

namespace {

// A design made of cone skirts (one per layer, inner first), pinned along each waistline.
GarmentDesign cone_skirts(const BodyLandmarks& lm, const std::vector<std::pair<Cone, std::string>>& cones) {
  GarmentDesign d;
  auto lays = std::make_shared<std::vector<SkirtLayout>>();
  double x_offset = 0;
  for (const auto& [c, name] : cones) {
    lays->push_back(add_cone_skirt(d.pattern, c, x_offset, name));
    x_offset = pattern_max_x(d.pattern) + 0.1;
  }
  finish_cone_design(d, lays, lm, cones.size() > 1);
  return d;
}

}  // namespace

GarmentDesign design_skirt_short(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  return cone_skirts(lm, {{skirt_cone(lm, 0.42 * s, 0.22 * s, 0.015), "skirt"}});
}

GarmentDesign design_skirt_long(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  return cone_skirts(lm, {{skirt_cone(lm, lm.waist_y - lm.floor - 0.15 * s, 0.20 * s, 0.015), "skirt"}});
}

GarmentDesign design_skirt_layered(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  return cone_skirts(
      lm, {{skirt_cone(lm, 0.55 * s, 0.12 * s, 0.015), "under"}, {skirt_cone(lm, 0.36 * s, 0.30 * s, 0.03), "over"}});
}

}  // namespace sim

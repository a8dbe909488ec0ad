// How one garment of the catalogue is made: its sewing pattern for a body, where each
// pattern point goes around the body's rest pose, which points are pinned to the body and
// which layer each panel is. One design function per garment (garment_skirts.cpp,
// garment_tubes.cpp, garment_tshirt.cpp, garment_pants.cpp, garment_pleats.cpp,
// garment_dress.cpp, garment_tiers.cpp); gdsr/sim/garments.cpp lists them by name.
#pragma once

#include "gdsr/sim/body_landmarks.hpp"
#include "gdsr/sim/pattern.hpp"

#include <functional>

namespace sim {

struct GarmentDesign {
  Pattern pattern;  // panels in metres
  // 3-D rest position (metres) of the point uv of panel `panel`.
  std::function<gdsr::Vec3(int panel, const gdsr::Vec2& uv)> place;
  // True for pattern points attached to the body (e.g. a waistband); empty: none.
  std::function<bool(int panel, const gdsr::Vec2& uv)> pinned;
  // Layer id of a panel (0 = innermost); empty: a one-layer garment (no layer ids at all).
  std::function<int(int panel)> layer;
};

GarmentDesign design_skirt_short(const BodyLandmarks& lm);
GarmentDesign design_skirt_long(const BodyLandmarks& lm);
GarmentDesign design_skirt_layered(const BodyLandmarks& lm);
GarmentDesign design_top(const BodyLandmarks& lm);
GarmentDesign design_shorts(const BodyLandmarks& lm);
// The paper's five training garments.
GarmentDesign design_tshirt(const BodyLandmarks& lm);  // long sleeves; needs arms clear of the trunk
GarmentDesign design_pants(const BodyLandmarks& lm);
GarmentDesign design_skirt_pleated(const BodyLandmarks& lm);
GarmentDesign design_dress_layered(const BodyLandmarks& lm);  // layers 0, 1
GarmentDesign design_skirt_tiered(const BodyLandmarks& lm);   // layers 0, 1, 2

}  // namespace sim

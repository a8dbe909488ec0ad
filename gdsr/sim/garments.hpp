// The garment catalogue: sewing patterns with a rest placement around a body's rest pose.
// The body is Y-up (metres, feet at its lowest point); landmarks (waist height, hip radius,
// shoulder height...) are measured from body_rest, so any human-sized body fits. The LR and
// HR versions of a garment come from the same pattern (identical UV outlines).
#pragma once

#include "gdsr/geometry/mesh.hpp"
#include "gdsr/sim/body_landmarks.hpp"
#include "gdsr/sim/pattern.hpp"

#include <string>
#include <vector>

namespace sim {

struct Garment {
  gdsr::GarmentMesh mesh;   // V = rest placement around the body rest pose (metres), UV = flat pattern (metres)
  std::vector<int> pinned;  // welded vertices attached to the body (e.g. waistband), may be empty
  std::string name;
  double particle_distance = 0;  // metres
};

// The catalogue's names: "skirt_short", "skirt_long", "top", "shorts", "skirt_layered", and
// the paper's five training garments "tshirt" (long sleeves), "pants", "skirt_pleated",
// "dress_layered" (2 layers), "skirt_tiered" (long skirt with 3 lace tiers).
std::vector<std::string> garment_names();

// The rest pose a garment is cut for, as gdsr::BodyOptions::rest_arm_drop_degrees: 45 (an
// A-pose) for the t-shirt, whose T-pose sleeves dragged the shoulders down off the body once
// the arms came down; -1 (the motion file's rest pose) for the rest.
double rest_arm_drop_degrees(const std::string& name);

// The sewing pattern of a garment for a body (sizes follow the landmarks).
Pattern garment_pattern(const std::string& name, const BodyLandmarks& lm);

// Meshes the pattern at particle_distance_m (metres) and places it around body_rest.
// Throws gdsr::Error for an unknown name or a body without a trunk.
Garment make_garment(const std::string& name, double particle_distance_m, const gdsr::TriMesh& body_rest);

}  // namespace sim

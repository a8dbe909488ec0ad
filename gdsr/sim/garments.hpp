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

// Substeps between body contact refreshes a garment is simulated with (SimParams::contact_every,
// `solver_default` for most). A contact is the plane through the closest body point, kept until
// the next refresh; in a closing crease the plane of one side does not see the other side
// coming. 3 for the t-shirt, whose sleeves sit in the crook of a bending elbow: every 5th
// substep, on salsa 61_03 (4 s from 2 s) cloth lay more than 5 mm inside the body outside pinches
// in 23 LR (30 mm) / 14 HR (10 mm) frames, up to 20 mm deep in the crook; every 3rd, 2 / 1 (60_02:
// 14 / 9 -> 1 / 2; with the friction nudged by 1e-5 to 6e-5 at 30 mm, 6-23 frames at 5 and 0-3 at 3
// in 6 runs each). 5 for the rest: fresher contacts press loose cloth harder into a closing hip
// crease, where it knots. On the lunge of CMU walk 131_01 (10 mm, from 2 s, the friction nudged
// twice; the nudged runs 2.5 s), HR frames free of self-intersections, every 5th / 3rd substep:
// pants 100, 100, 100 / 86.8, 63.7, 100%; skirt_pleated 86.0, 86.8, 84.6 / 35.3, 52.7, 100%. Cost of
// 3: 4-11% more CPU time a frame (HR t-shirt 1.69 -> 1.84 s on 61_03).
int body_contact_every(const std::string& name, int solver_default);

// The sewing pattern of a garment for a body (sizes follow the landmarks).
Pattern garment_pattern(const std::string& name, const BodyLandmarks& lm);

// Meshes the pattern at particle_distance_m (metres) and places it around body_rest.
// Throws gdsr::Error for an unknown name or a body without a trunk.
Garment make_garment(const std::string& name, double particle_distance_m, const gdsr::TriMesh& body_rest);

}  // namespace sim

// The garment catalogue: sewing patterns with a rest placement around a body's rest pose.
// The body is Y-up (metres, feet at its lowest point); landmarks (waist height, hip radius,
// shoulder height...) are measured from body_rest, so any human-sized body fits. The LR and
// HR versions of a garment come from the same pattern (identical UV outlines).
#pragma once

#include "gdsr/mesh.hpp"
#include "sim/pattern.hpp"

#include <string>
#include <vector>

namespace sim {

struct Garment {
  gdsr::GarmentMesh mesh;   // V = rest placement around the body rest pose (metres), UV = flat pattern (metres)
  std::vector<int> pinned;  // welded vertices attached to the body (e.g. waistband), may be empty
  std::string name;
  double particle_distance = 0;  // metres
};

// "skirt_short", "skirt_long", "top", "shorts", "skirt_layered".
std::vector<std::string> garment_names();

// Landmarks of a standing body (Y up), metres.
struct BodyLandmarks {
  double floor = 0, height = 0;       // lowest y, total height
  gdsr::Vec3 axis = gdsr::Vec3::Zero();  // x, z of the trunk axis (y unused)
  double waist_y = 0, hip_y = 0, crotch_y = 0, armpit_y = 0, shoulder_y = 0, neck_y = 0;
  double waist_r = 0, hip_r = 0;      // max horizontal distance of the trunk from the axis
  double chest_r = 0, shoulder_halfwidth = 0, leg_x = 0, thigh_r = 0;
};
BodyLandmarks measure_body(const gdsr::TriMesh& body_rest);

// The sewing pattern of a garment for a body (sizes follow the landmarks).
Pattern garment_pattern(const std::string& name, const BodyLandmarks& lm);

// Meshes the pattern at particle_distance_m (metres) and places it around body_rest.
// Throws std::runtime_error for an unknown name or a body without a trunk.
Garment make_garment(const std::string& name, double particle_distance_m, const gdsr::TriMesh& body_rest);

}  // namespace sim

// A flat square garment for cloth tests: one panel of side `side` metres meshed at particle
// distance h, placed horizontally at height y centred over x = z = 0. The pattern's (u, v)
// maps to (x, -z), so the counter-clockwise UV faces have upward normals. Meshes of one side
// at two particle distances share their UV layout (an LR / HR pair).
#pragma once

#include "gdsr/sim/garments.hpp"
#include "gdsr/sim/pattern.hpp"

namespace gdsr_test {

inline sim::Garment square_cloth(double side, double h, double y) {
  sim::Pattern p;
  p.panels.push_back({"square", {gdsr::Vec2(0, 0), gdsr::Vec2(side, 0), gdsr::Vec2(side, side), gdsr::Vec2(0, side)}});
  auto pm = sim::mesh_pattern(p, h);
  sim::place_pattern(pm,
                     [&](int, const gdsr::Vec2& uv) { return gdsr::Vec3(uv.x() - side / 2, y, side / 2 - uv.y()); });
  sim::Garment g;
  g.mesh = pm.mesh;
  g.name = "square";
  g.particle_distance = h;
  return g;
}

}  // namespace gdsr_test

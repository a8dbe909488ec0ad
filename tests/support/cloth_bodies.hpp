// Analytic closed bodies (outward-oriented triangle meshes, metres, Y up) for tests and
// benchmarks of the cloth solver: a UV sphere and a standing "mannequin" made of a trunk
// capsule and two leg capsules (separate closed components, overlapping).
#pragma once

#include "gdsr/geometry/mesh.hpp"

namespace sim {

// Sphere of radius r around c; rings x segments quads split into triangles.
gdsr::TriMesh make_sphere(const gdsr::Vec3& c, double r, int rings = 24, int segments = 48);

// Vertical capsule (axis along y) from y0 to y1 (cap tips), radius r, centred at (x, z).
gdsr::TriMesh make_capsule(double x, double z, double y0, double y1, double r, int rings = 32, int segments = 48);

// Trunk capsule (y from 0.78 to 1.62 m, radius 0.15) and legs (y 0 to 0.95, radius 0.075 at
// x = +-0.085): about 1.62 m tall, scaled by height / 1.62.
gdsr::TriMesh make_mannequin(double height = 1.62);

// Concatenates meshes (faces re-indexed).
gdsr::TriMesh merge_meshes(const gdsr::TriMesh& a, const gdsr::TriMesh& b);

}  // namespace sim

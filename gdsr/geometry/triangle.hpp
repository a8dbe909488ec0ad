// Closest point on a 3-D triangle (Ericson, Real-Time Collision Detection 5.1.5): the one
// implementation used by body queries, model features, the simulator and its metrics.
// Units are the caller's (metres everywhere in gdsr).
#pragma once

#include "gdsr/geometry/mesh.hpp"

namespace gdsr {

// Which Voronoi region of the triangle the closest point lies in.
enum class TriangleRegion { Face = 0, VertexA = 1, VertexB = 2, VertexC = 3, EdgeAB = 4, EdgeBC = 5, EdgeCA = 6 };

struct TriangleClosest {
  Vec3 point;  // closest point on triangle (a, b, c)
  Vec3 bary;   // its barycentric coordinates (u, v, w), u + v + w = 1, all >= 0
  TriangleRegion region;
};

// Closest point of triangle (a, b, c) to p. A degenerate triangle (zero area) whose
// interior test cannot decide returns vertex a.
TriangleClosest closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace gdsr

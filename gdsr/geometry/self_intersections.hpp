// Self-intersections of a triangle mesh, counted by CGAL's
// Polygon_mesh_processing::self_intersections (an independent yardstick: none of the
// simulator's collision code is involved). Exact predicates (Epick kernel), so the count does
// not depend on a tolerance: two triangles intersect or they do not.
//
// What counts as an intersecting pair (CGAL 5.5's rules, checked in
// tests/gdsr/geometry/test_self_intersections.cpp):
//   - faces sharing no vertex: any common point (crossing, or merely touching);
//   - faces sharing exactly one vertex: counted only if they meet somewhere else too (the edge
//     opposite the shared vertex of one face hits the other face); meeting at the shared vertex
//     alone is not an intersection;
//   - faces sharing an edge: counted only if they are coplanar and overlap (the fold is flat
//     and folded back onto itself); any other pair of edge neighbours is not an intersection.
// So adjacent faces never count for their shared vertex/edge, which is the "non-adjacent
// triangle pairs" of the validity figures. Degenerate (collinear) faces are counted apart and
// take part in no pair (CGAL builds no box for them).
// Faces that cannot join an oriented 2-manifold (an edge with a third face, inconsistent
// orientation, a non-manifold vertex fan) are left out of the test and counted in `skipped_faces`.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <utility>
#include <vector>

namespace gdsr {

struct SelfIntersections {
  long pairs = 0;                         // intersecting pairs of distinct faces (each pair once)
  long degenerate_faces = 0;              // faces with collinear corners
  long skipped_faces = 0;                 // faces left out (non-manifold, see above)
  std::vector<std::pair<int, int>> list;  // the pairs (f, g), f < g, sorted; only if asked for
};

// V: vertices x 3 (any unit), F: faces x 3 indices into V. Throws gdsr::Error on an index out
// of range or a non-finite vertex. list_pairs = true fills `list`.
SelfIntersections self_intersections(const Points3& V, const Faces& F, bool list_pairs = false);

}  // namespace gdsr

#include "gdsr/geometry/self_intersections.hpp"

#include "gdsr/error.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <iterator>
#include <string>

namespace gdsr {

SelfIntersections self_intersections(const Points3& V, const Faces& F, bool list_pairs) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using SM = CGAL::Surface_mesh<K::Point_3>;
  using FaceIndex = SM::Face_index;
  if (!V.allFinite()) fail("self_intersections", "non-finite vertex position");
  if (F.rows() > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= V.rows()))
    fail("self_intersections", "face index out of range (" + std::to_string(V.rows()) + " vertices)");

  SelfIntersections out;
  SM sm;
  std::vector<SM::Vertex_index> vi(V.rows());
  for (long i = 0; i < V.rows(); ++i) vi[i] = sm.add_vertex(K::Point_3(V(i, 0), V(i, 1), V(i, 2)));
  std::vector<int> original;  // Surface_mesh face index -> row of F
  original.reserve(F.rows());
  for (int f = 0; f < F.rows(); ++f) {
    const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
    if (a == b || b == c || a == c) {  // repeated corner: degenerate, and Surface_mesh refuses it
      ++out.degenerate_faces;
      continue;
    }
    const FaceIndex fi = sm.add_face(vi[a], vi[b], vi[c]);
    if (fi == SM::null_face()) {
      ++out.skipped_faces;
      continue;
    }
    if (static_cast<size_t>(fi.idx()) != original.size()) fail("self_intersections", "unexpected CGAL face numbering");
    original.push_back(f);
  }

  std::vector<std::pair<FaceIndex, FaceIndex>> found;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(found));
  for (const auto& [f, g] : found) {
    if (f == g) {  // CGAL reports a degenerate face as the pair (f, f)
      ++out.degenerate_faces;
      continue;
    }
    ++out.pairs;
    if (list_pairs) {
      const int a = original[f.idx()], b = original[g.idx()];
      out.list.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(out.list.begin(), out.list.end());
  return out;
}

}  // namespace gdsr

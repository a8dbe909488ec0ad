// The CGAL self-intersection counter on closed-form cases: crossing and disjoint triangles,
// CGAL's rules for faces sharing a vertex or an edge, a strip folded through itself, and clean
// meshes (flat grid, closed tube, sphere) with none.
#include "gdsr/error.hpp"
#include "gdsr/geometry/self_intersections.hpp"
#include "tests/support/cloth_bodies.hpp"
#include "tests/support/grid_garment.hpp"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <set>
#include <vector>

using gdsr::Faces;
using gdsr::Points3;

namespace {

gdsr::SelfIntersections count(const std::vector<gdsr::Vec3>& pts, const std::vector<std::array<int, 3>>& tris) {
  Points3 V(pts.size(), 3);
  for (size_t i = 0; i < pts.size(); ++i) V.row(i) = pts[i].transpose();
  Faces F(tris.size(), 3);
  for (size_t f = 0; f < tris.size(); ++f) F.row(f) << tris[f][0], tris[f][1], tris[f][2];
  return gdsr::self_intersections(V, F, true);
}

using P = gdsr::Vec3;

}  // namespace

TEST_CASE("gdsr: self-intersections of two separate triangles: crossing 1 pair, disjoint or apart 0") {
  // Triangle 0 in z = 0; triangle 1 stands upright in x = 0.2 and pierces it.
  const std::vector<P> pts = {P(0, 0, 0), P(1, 0, 0), P(0, 1, 0), P(0.2, 0.2, -1), P(0.2, 0.2, 1), P(0.2, -1, 0.5)};
  const auto hit = count(pts, {{0, 1, 2}, {3, 4, 5}});
  CHECK(hit.pairs == 1);
  REQUIRE(hit.list.size() == 1);
  CHECK(hit.list[0] == std::make_pair(0, 1));
  // The same upright triangle moved to x = 2: no common point.
  std::vector<P> moved = pts;
  for (int k = 3; k < 6; ++k) moved[k].x() = 2;
  CHECK(count(moved, {{0, 1, 2}, {3, 4, 5}}).pairs == 0);
  // Merely touching (a corner on the other face) counts: faces without a shared vertex may
  // not meet at all.
  const std::vector<P> touch = {P(0, 0, 0), P(1, 0, 0), P(0, 1, 0), P(0.2, 0.2, 0), P(0.2, 0.2, 1), P(0.5, 0.5, 1)};
  CHECK(count(touch, {{0, 1, 2}, {3, 4, 5}}).pairs == 1);
}

TEST_CASE("gdsr: self-intersections: faces sharing a vertex count only if they also meet elsewhere") {
  // Face 0 in z = 0; every other face shares its vertex 0 (the origin).
  const std::vector<P> pts = {P(0, 0, 0),     P(1, 0, 0),      P(0, 1, 0),
                              P(1, 1, 1),     P(-1, 1, 1),      // 3, 4: a fan above: meets face 0 only at the origin
                              P(0.2, 0.2, 1), P(0.2, 0.2, -1),  // 5, 6: opposite edge pierces face 0
                              P(0.5, 0.1, 0), P(0.1, 0.5, 0)};  // 7, 8: coplanar, inside face 0
  CHECK(count(pts, {{0, 1, 2}, {0, 3, 4}}).pairs == 0);
  CHECK(count(pts, {{0, 1, 2}, {0, 5, 6}}).pairs == 1);
  CHECK(count(pts, {{0, 1, 2}, {0, 7, 8}}).pairs == 1);
}

TEST_CASE("gdsr: self-intersections: edge neighbours count only when folded flat onto each other") {
  // Face 0 = (0, 1, 2) in z = 0; face 1 = (1, 0, 3) shares the edge 0-1 (consistent orientation).
  const P a(0, 0, 0), b(1, 0, 0), c(0.3, 1, 0);
  CHECK(count({a, b, c, P(0.5, -1, 0)}, {{0, 1, 2}, {1, 0, 3}}).pairs == 0);    // flat sheet
  CHECK(count({a, b, c, P(0.5, -1, 0.7)}, {{0, 1, 2}, {1, 0, 3}}).pairs == 0);  // a crease
  CHECK(count({a, b, c, P(0.5, 0.5, 0)}, {{0, 1, 2}, {1, 0, 3}}).pairs == 1);   // folded back flat: overlap
}

TEST_CASE("gdsr: self-intersections: degenerate faces are counted apart, pairs need real triangles") {
  const auto r = count({P(0, 0, 0), P(1, 0, 0), P(2, 0, 0), P(0, 1, 0)}, {{0, 1, 2}, {0, 1, 3}});
  CHECK(r.degenerate_faces == 1);
  CHECK(r.pairs == 0);
  CHECK(count({P(0, 0, 0), P(1, 0, 0), P(0, 1, 0)}, {{0, 0, 2}}).degenerate_faces == 1);
}

TEST_CASE("gdsr: self-intersections of a strip folded through itself: 3 pairs, 4 faces, in closed form") {
  // A strip one quad wide (y in [0, 0.3]) along a polyline in x-z: flat A=(0,0) -> B=(1,0) in
  // 20 quads, up to C=(1,0.5) in 5 quads, then down through its own flat part to D=(0.45,-0.3)
  // in 7 quads. C-D crosses z = 0 at x = 1 - 0.55 * 0.625 = 0.65625: inside flat quad 13
  // (x in [0.65, 0.70], 12.5% in), and 62.5% along C-D, i.e. inside C-D quad 4 (4.375 of 7)
  // = strip quad 20 + 5 + 4 = 29. The crossing line runs across the strip (along y); each quad
  // is cut by its diagonal, so the line meets both triangles of either quad: the two lower
  // triangles meet at y = 0, the two upper at y = 0.3, and one mixed pair overlaps because the
  // quads are cut at different fractions (12.5% vs 37.5% / 62.5%): 3 pairs, faces 26, 27, 58, 59.
  std::vector<gdsr::Vec2> path;
  auto segment = [&](gdsr::Vec2 from, gdsr::Vec2 to, int n) {
    for (int k = path.empty() ? 0 : 1; k <= n; ++k) path.push_back(from + (to - from) * (static_cast<double>(k) / n));
  };
  segment({0, 0}, {1, 0}, 20);
  segment({1, 0}, {1, 0.5}, 5);
  segment({1, 0.5}, {0.45, -0.3}, 7);
  const int K = static_cast<int>(path.size());
  Points3 V(2 * K, 3);
  for (int k = 0; k < K; ++k) {
    V.row(2 * k) << path[k].x(), 0.0, path[k].y();
    V.row(2 * k + 1) << path[k].x(), 0.3, path[k].y();
  }
  Faces F(2 * (K - 1), 3);
  for (int k = 0; k + 1 < K; ++k) {
    const int a = 2 * k, c = 2 * k + 1, b = 2 * k + 2, d = 2 * k + 3;
    F.row(2 * k) << a, b, d;
    F.row(2 * k + 1) << a, d, c;
  }
  const auto r = gdsr::self_intersections(V, F, true);
  CHECK(r.pairs == 3);
  std::set<int> faces;
  for (auto [f, g] : r.list) faces.insert({f, g});
  CHECK(faces == std::set<int>{26, 27, 58, 59});
  CHECK(r.skipped_faces == 0);
  CHECK(r.degenerate_faces == 0);
  // Unfolded (C-D turned up instead of through the sheet), no pair is left.
  Points3 up = V;
  for (int k = 25; k < K; ++k) up(2 * k, 2) = up(2 * k + 1, 2) = 0.5 + (0.5 - V(2 * k, 2));
  CHECK(gdsr::self_intersections(up, F).pairs == 0);
}

TEST_CASE("gdsr: self-intersections of clean meshes: flat grid, closed tube, sphere have none") {
  const gdsr::GarmentMesh grid = gdsr_test::grid_garment(gdsr_test::GridSpec(12, 9, 0.6, 0.45));
  CHECK(gdsr::self_intersections(grid.V, grid.F).pairs == 0);
  const gdsr::GarmentMesh tube = gdsr_test::grid_garment(gdsr_test::GridSpec(16, 4, 0.9, 0.3).tube());
  const auto t = gdsr::self_intersections(tube.V, tube.F);
  CHECK(t.pairs == 0);
  CHECK(t.skipped_faces == 0);
  const gdsr::TriMesh sphere = sim::make_sphere(gdsr::Vec3(0.1, 1.2, -0.3), 0.25);
  const auto s = gdsr::self_intersections(sphere.V, sphere.F);
  CHECK(s.pairs == 0);
  CHECK(s.degenerate_faces == 0);
  // Push the upper half (above the equator ring) 0.3 m down through the lower one: now it
  // pierces itself.
  Points3 pushed = sphere.V;
  for (long i = 0; i < pushed.rows(); ++i)
    if (pushed(i, 1) > 1.2 + 1e-9) pushed(i, 1) -= 0.3;
  CHECK(gdsr::self_intersections(pushed, sphere.F).pairs > 0);
}

TEST_CASE("gdsr: self-intersections: a third face on an edge is skipped, bad input throws") {
  // Faces 0 and 1 share the edge 0-1; face 2 would be its third face: left out, counted.
  const auto r =
      count({P(0, 0, 0), P(1, 0, 0), P(0.5, 1, 0), P(0.5, -1, 0), P(0.5, 0, 1)}, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  CHECK(r.skipped_faces == 1);
  CHECK(r.pairs == 0);
  Points3 V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  Faces bad(1, 3);
  bad << 0, 1, 3;
  CHECK_THROWS_AS(gdsr::self_intersections(V, bad), gdsr::Error);
  Faces F(1, 3);
  F << 0, 1, 2;
  V(1, 0) = std::nan("");
  CHECK_THROWS_AS(gdsr::self_intersections(V, F), gdsr::Error);
}

// Flesh that gives way (gdsr/body/body_yield.hpp), judged by CGAL's self-intersection test and
// by where two overlapping spheres must meet.
#include "gdsr/body/body.hpp"
#include "gdsr/body/body_yield.hpp"
#include "gdsr/data/validity.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/self_intersections.hpp"
#include "tests/support/cloth_bodies.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

using namespace gdsr;

namespace {

// Two spheres of radius r centred at x = -c and x = +c, one mesh (two closed components).
TriMesh two_spheres(double r, double c) {
  return sim::merge_meshes(sim::make_sphere(Vec3(-c, 0, 0), r, 32, 64), sim::make_sphere(Vec3(c, 0, 0), r, 32, 64));
}

}  // namespace

TEST_CASE("body_yield: two overlapping spheres give way to meet gap apart at the plane between them") {
  const double r = 0.1, c = 0.07, gap = 0.004;  // overlap 2 (r - c) = 60 mm deep on the axis
  TriMesh m = two_spheres(r, c);
  const Eigen::Index half = m.V.rows() / 2;
  REQUIRE(self_intersections(m.V, m.F).pairs > 0);
  const std::vector<char> buried = buried_vertices(m.F, m.V, gap);
  // Buried: exactly the vertices whose point gap outside lies inside the other sphere.
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    const Vec3 p = m.V.row(i).transpose();
    const Vec3 own(i < half ? -c : c, 0, 0), other(i < half ? c : -c, 0, 0);
    const double outside_by = ((p + gap * (p - own).normalized()) - other).norm() - r;
    if (std::abs(outside_by) > 1e-3) CHECK_MESSAGE(buried[i] == (outside_by < 0), "vertex " << i);
  }

  const Points3 before = m.V;
  BodyYieldOptions opt;
  opt.gap = gap;
  const Points3 rest = two_spheres(r, 0.3).V;  // the parts, apart
  const BodyYield y = yield_self_overlap(m.F, m.V, rest, {}, opt);
  CHECK(y.buried_left == 0);
  CHECK(y.vertices_moved > 0);
  // No triangle of one sphere crosses the other any more (CGAL).
  CHECK(self_intersections(m.V, m.F).pairs == 0);
  // Each gave way by half: the deepest points (60 mm + the gap) moved 32 mm, to -gap / 2 and
  // +gap / 2. Off the axis the surfaces bulge by less than the mesh's chord (r * pi / 32 = 10 mm).
  const double left_max = m.V.topRows(half).col(0).maxCoeff(), right_min = m.V.bottomRows(half).col(0).minCoeff();
  CHECK(left_max == doctest::Approx(-gap / 2).scale(1).epsilon(0.0015));
  CHECK(right_min == doctest::Approx(gap / 2).scale(1).epsilon(0.0015));
  CHECK(y.max_move == doctest::Approx(0.5 * (2 * (r - c) + gap)).epsilon(0.05));
  // Vertices that were not in the other sphere or near it are untouched, bit for bit.
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (std::abs(before(i, 0)) > 0.03 + 0.01) CHECK(m.V.row(i) == before.row(i));
  // The two spheres give way alike (the mesh is symmetric about x = 0).
  const double left_moved = (m.V - before).topRows(half).rowwise().norm().sum();
  const double right_moved = (m.V - before).bottomRows(half).rowwise().norm().sum();
  CHECK(left_moved == doctest::Approx(right_moved).epsilon(1e-6));
  // The same input gives the same output.
  TriMesh again = two_spheres(r, c);
  yield_self_overlap(again.F, again.V, rest, {}, opt);
  CHECK(again.V == m.V);
  // Within part_separation of each other in the rest pose, the two are one part folded onto
  // itself (a joint's crease): left as they are.
  TriMesh fold = two_spheres(r, c);
  opt.part_separation = 1.0;
  const BodyYield none = yield_self_overlap(fold.F, fold.V, rest, {}, opt);
  CHECK(none.vertices_moved == 0);
  CHECK(fold.V == before);
  CHECK_THROWS_WITH_AS(yield_self_overlap(fold.F, fold.V, rest.topRows(10), {}, opt),
                       "yield_self_overlap: rest pose and frame differ in vertex count", Error);
  CHECK_THROWS_WITH_AS(yield_self_overlap(fold.F, fold.V, rest, std::vector<int>(10, 0), opt),
                       "yield_self_overlap: segment labels and frame differ in vertex count", Error);
  // A non-finite vertex is refused (by the ray caster), not carried into the frame.
  fold.V(5, 1) = std::nan("");
  CHECK_THROWS_AS(yield_self_overlap(fold.F, fold.V, rest, {}, opt), Error);
}

TEST_CASE("body_yield: a surface that does not pass through itself is returned bit for bit") {
  TriMesh m = two_spheres(0.1, 0.11);  // 20 mm apart: more than the gap
  const Points3 before = m.V;
  const BodyYield y = yield_self_overlap(m.F, m.V, two_spheres(0.1, 0.3).V, {});
  CHECK(y.vertices_moved == 0);
  CHECK(y.max_move == 0);
  CHECK(m.V == before);
  // Closer than the gap (but not touching): each side steps back, to the gap.
  TriMesh near = two_spheres(0.1, 0.101);  // 2 mm apart
  BodyYieldOptions opt;
  opt.gap = 0.004;
  yield_self_overlap(near.F, near.V, two_spheres(0.1, 0.3).V, {}, opt);
  const Eigen::Index half = near.V.rows() / 2;
  CHECK(near.V.bottomRows(half).col(0).minCoeff() - near.V.topRows(half).col(0).maxCoeff() >= 0.004 - 1e-4);
}

TEST_CASE("body_yield: the kneel of CMU 131_01 no longer passes the thigh into the belly (CGAL)") {
  // 2.95-3.45 s of the clip: the right thigh raised into the lower belly, the left forearm at
  // the back. Counted as the validity figures count "the body crosses itself": two faces
  // intersect (CGAL) whose corners were all farther than 0.15 m apart in the first frame.
  BodyOptions o;
  o.start_seconds = 2.95;
  o.max_seconds = 0.5;
  o.arm_clearance = 0.01;  // as gdsr data make
  const std::string walk = std::string(GDSR_SHARED_DIR) + "/motions/cmu-walk/131_01.bvh";
  const BodySequence skinned = load_body_sequence(walk, o);
  o.yield_gap = 0.004;
  const BodySequence yielded = load_body_sequence(walk, o);
  REQUIRE(yielded.num_frames() == skinned.num_frames());
  int crossing_before = 0, crossing_after = 0;
  for (int f = 0; f < skinned.num_frames(); ++f) {
    crossing_before += body_crosses_itself(skinned.frames[f], skinned.F, skinned.rest_V, 0.15);
    crossing_after += body_crosses_itself(yielded.frames[f], yielded.F, yielded.rest_V, 0.15);
  }
  MESSAGE("frames crossing itself: " << crossing_before << " as skinned, " << crossing_after << " given way, of "
                                     << skinned.num_frames() << "; deepest move "
                                     << 1e3 * yielded.yields.max_move_overall() << " mm");
  CHECK(crossing_before >= 10);
  CHECK(crossing_after <= 1);
  CHECK(yielded.yields.yielded_frames() >= crossing_before);
  // The rest pose (frame 0, where garments are put on) stays as skinned: nothing overlaps there.
  CHECK(yielded.frames[0] == skinned.frames[0]);
  CHECK(yielded.rest_V == skinned.rest_V);
  // Off by default.
  CHECK(BodyOptions{}.yield_gap == 0);
  CHECK(skinned.yields.max_move.empty());
}

TEST_CASE("body_yield: a limb pressed into the trunk, told apart by segment labels, gives way by the overlap") {
  // A "thigh" sphere of radius 0.08 m whose surface reaches 2 cm into a "trunk" sphere of radius
  // 0.15 m; in the rest pose they stand apart.
  const TriMesh trunk = sim::make_sphere(Vec3(0, 0, 0), 0.15, 32, 64);
  TriMesh m = sim::merge_meshes(trunk, sim::make_sphere(Vec3(0.21, 0, 0), 0.08, 24, 48));
  const Eigen::Index nt = trunk.V.rows();
  Points3 rest = m.V;
  rest.bottomRows(m.V.rows() - nt).col(0).array() += 0.5;
  std::vector<int> segment(m.V.rows(), 0);
  std::fill(segment.begin() + nt, segment.end(), 1);
  REQUIRE(self_intersections(m.V, m.F).pairs > 0);
  const BodyYield y = yield_self_overlap(m.F, m.V, rest, segment);
  CHECK(y.vertices_moved > 0);
  CHECK(y.buried_left == 0);
  CHECK(self_intersections(m.V, m.F).pairs == 0);
  // Each side half the 20 mm overlap plus half the 4 mm gap, on the axis; less off it.
  CHECK(y.max_move == doctest::Approx(0.5 * (0.02 + 0.004)).epsilon(0.1));
}

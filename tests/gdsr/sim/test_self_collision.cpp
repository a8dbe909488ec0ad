// Cloth self-collision, judged by an independent yardstick: CGAL's
// Polygon_mesh_processing::self_intersections (gdsr/geometry/self_intersections.hpp) on the simulated
// triangle mesh, never the solver's own collision code.
#include <doctest/doctest.h>

#include <utility>

#include "tests/support/cloth_bodies.hpp"
#include "tests/support/crumpled_sheets.hpp"
#include "tests/support/omp_threads.hpp"
#include "tests/support/square_cloth.hpp"
#include "gdsr/sim/cloth_self_collision.hpp"
#include "gdsr/sim/cloth_solver.hpp"
#include "gdsr/sim/cloth_tracking.hpp"
#include "gdsr/sim/garments.hpp"
#include "gdsr/sim/pattern.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/self_intersections.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/triangle.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>
#include <fstream>

using gdsr::Points3;
using gdsr::Vec2;
using gdsr::Vec3;

namespace {

// Horizontal square sheet (side m) at height y centred over x = z = 0 at particle distance h.
gdsr::GarmentMesh sheet(double side, double h, double y) { return gdsr_test::square_cloth(side, h, y).mesh; }

// Lower sheet (0.5 m, nl vertices first) clamped along its border (no body: pinned vertices
// are fixed); the upper sheet, smaller and turned, 0.3 m above it, at particle distance h.
sim::Garment two_sheets(double h, int& nl) {
  auto lower = sheet(0.5, h, 0.0);
  auto upper = sheet(0.36, h, 0.3);
  const double c = std::cos(0.5), s = std::sin(0.5);
  for (int v = 0; v < upper.V.rows(); ++v) {
    const double x = upper.V(v, 0), z = upper.V(v, 2);
    upper.V(v, 0) = c * x - s * z;
    upper.V(v, 2) = s * x + c * z;
  }
  sim::Garment g;
  g.name = "two sheets";
  g.particle_distance = h;
  g.mesh = gdsr_test::merge_garment_meshes(lower, upper);
  nl = static_cast<int>(lower.V.rows());
  for (int v = 0; v < nl; ++v)
    if (std::max(std::abs(lower.V(v, 0)), std::abs(lower.V(v, 2))) > 0.25 - 1e-9) g.pinned.push_back(v);
  return g;
}

// The two sheets at particle distance h with a solver for them (no body, no settle).
struct TwoSheetDrop {
  int nl = 0;  // lower sheet's vertex count
  sim::Garment g;
  sim::SimParams p;
  std::unique_ptr<sim::ClothSolver> solver;
  explicit TwoSheetDrop(double h, double self_thickness = -1) : g(two_sheets(h, nl)) {
    p.settle_frames = 0;
    if (self_thickness > 0) p.self_thickness = self_thickness;
    solver = std::make_unique<sim::ClothSolver>(g, gdsr::Faces(), Points3(), p);
  }
};

// A 0.2 m sheet 2 cm above a 0.4 m one clamped along its border, its last 5 cm folded
// straight down through the lower sheet (particle distance 20 mm).
sim::Garment flap_through_sheet() {
  const double h = 0.02;
  auto lower = sheet(0.4, h, 0.0);
  auto upper = sheet(0.2, h, 0.02);
  for (int v = 0; v < upper.V.rows(); ++v)
    if (upper.V(v, 0) > 0.05) {
      upper.V(v, 1) = 0.02 - (upper.V(v, 0) - 0.05);
      upper.V(v, 0) = 0.05;
    }
  sim::Garment g;
  g.name = "flap";
  g.particle_distance = h;
  g.mesh = gdsr_test::merge_garment_meshes(lower, upper);
  for (int v = 0; v < lower.V.rows(); ++v)
    if (std::max(std::abs(lower.V(v, 0)), std::abs(lower.V(v, 2))) > 0.2 - 1e-9) g.pinned.push_back(v);
  return g;
}

// Self-contact pairs of faces F detected at `pressed`, cloth pressed through itself, without a
// tangle test (as the solver's detections within a frame); pushes into intersections refused or not.
std::unique_ptr<sim::SelfCollision> detected_pressed(const gdsr::Faces& F, const Points3& pressed, double slack,
                                                     double thickness, bool refuse) {
  auto sc = std::make_unique<sim::SelfCollision>(F, static_cast<int>(pressed.rows()));
  sc->set_refuse_crossing_pushes(refuse);
  sc->detect(pressed, Points3::Zero(pressed.rows(), 3), slack, thickness, false);
  return sc;
}

}  // namespace

TEST_CASE("self-collision: the CGAL yardstick counts crossing triangles and ignores neighbours") {
  auto a = sheet(0.2, 0.05, 0.0);
  CHECK((gdsr::self_intersections(a.V, a.F).pairs == 0));
  // A second sheet standing vertically through the first one crosses it.
  auto b = sheet(0.2, 0.05, 0.0);
  for (int v = 0; v < b.V.rows(); ++v) b.V.row(v) = Vec3(b.V(v, 0) + 0.013, b.V(v, 2) + 0.011, 0.007).transpose();
  const auto m = gdsr_test::merge_garment_meshes(a, b);
  CHECK(!(gdsr::self_intersections(m.V, m.F).pairs == 0));
}

namespace {

// Distance between segments p1q1 and p2q2, the yardstick of the broad-phase test below, by
// another road than the solver's closed form: the distance from p1 + s (q1 - p1) to the other
// segment is convex in s, so a ternary search over s finds its minimum.
double segment_distance(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2) {
  const Vec3 d2 = q2 - p2;
  auto to_second = [&](double s) {
    const Vec3 p = p1 + s * (q1 - p1);
    const double t = d2.squaredNorm() > 0 ? std::clamp((p - p2).dot(d2) / d2.squaredNorm(), 0.0, 1.0) : 0.0;
    return (p - (p2 + t * d2)).norm();
  };
  double lo = 0, hi = 1;
  for (int k = 0; k < 100; ++k) {  // (2/3)^100 ~ 2e-18 of the first segment's length
    const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
    if (to_second(m1) < to_second(m2))
      hi = m2;
    else
      lo = m1;
  }
  return to_second(0.5 * (lo + hi));
}

using gdsr_test::CrumpledSheets;

// Paths for a redetect `half` through the interval: 5% of the vertices (drawn with `seed`) leave
// their paths for new motions of up to 2 mm (moved, rest); the others go on along theirs.
struct LeftPaths {
  std::vector<char> moved;
  Points3 rest;
  LeftPaths(const Points3& motion, double half, unsigned seed) : moved(motion.rows(), 0), rest((1 - half) * motion) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int v = 0; v < static_cast<int>(motion.rows()); ++v)
      if (u(rng) > 0.9) moved[v] = 1, rest.row(v) = 0.002 * Eigen::RowVector3d(u(rng), u(rng), u(rng));
  }
};

}  // namespace

TEST_CASE("self-collision: detect keeps every pair within reach that a search over all pairs finds") {
  // Two crumpled 20 cm sheets 4 mm apart (random offsets up to 3 mm), still and with random
  // motions: detect keeps exactly the non-adjacent pairs whose two primitives' path boxes (x to
  // x + motion - the mean motion, grown by thickness / 2 + slack) overlap and whose distance is below their reach,
  // thickness + relative motion + 2 slack (the header's rule); without motion these are all
  // pairs closer than thickness + 2 slack. The edge-edge pairs come from every pair of several
  // scenes (chunks) of consecutive edges, so this also holds the chunks to one scene of all edges.
  const CrumpledSheets sheets(5);
  const auto& m = sheets.m;
  const Points3 &x = sheets.x, &moving = sheets.motion;
  const int nv = static_cast<int>(m.V.rows());
  const double thickness = 0.005, slack = 0.001, pad = 0.5 * thickness + slack;
  std::vector<std::array<int, 2>> edges;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = m.F(f, k), j = m.F(f, (k + 1) % 3);
      edges.push_back({std::min(i, j), std::max(i, j)});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const Points3& motion : {Points3(Points3::Zero(nv, 3)), moving}) {
    // Largest per-axis gap between the path boxes of two vertex sets (0: they overlap).
    const Eigen::RowVector3d mean = motion.colwise().mean();
    auto box_gap = [&](std::initializer_list<int> s, std::initializer_list<int> t) {
      Vec3 lo1 = Vec3::Constant(1e30), hi1 = -lo1, lo2 = lo1, hi2 = hi1;
      for (int v : s) {
        const Vec3 p = x.row(v), q = x.row(v) + motion.row(v) - mean;
        lo1 = lo1.cwiseMin(p).cwiseMin(q), hi1 = hi1.cwiseMax(p).cwiseMax(q);
      }
      for (int v : t) {
        const Vec3 p = x.row(v), q = x.row(v) + motion.row(v) - mean;
        lo2 = lo2.cwiseMin(p).cwiseMin(q), hi2 = hi2.cwiseMax(p).cwiseMax(q);
      }
      return (lo2 - hi1).cwiseMax(lo1 - hi2).cwiseMax(0.0).maxCoeff();
    };
    // Counts of pairs certainly kept and possibly kept (room for the float boxes' and the
    // distances' rounding).
    auto count = [&](double gap, double d, double reach, int& sure, int& maybe) {
      sure += gap < 2 * pad * (1 - 1e-5) && d < reach * (1 - 1e-9);
      maybe += gap < 2 * pad * (1 + 1e-5) && d < reach * (1 + 1e-9);
    };
    int vt_sure = 0, vt_maybe = 0, ee_sure = 0, ee_maybe = 0;
    for (int v = 0; v < nv; ++v)
      for (int f = 0; f < m.F.rows(); ++f) {
        const int i = m.F(f, 0), j = m.F(f, 1), k = m.F(f, 2);
        if (i == v || j == v || k == v) continue;
        double rel = 0;
        for (int w : {i, j, k}) rel = std::max(rel, (motion.row(v) - motion.row(w)).norm());
        const Vec3 p = x.row(v);
        const double d = (p - gdsr::closest_point_on_triangle(p, x.row(i), x.row(j), x.row(k)).point).norm();
        count(box_gap({v}, {i, j, k}), d, thickness + rel + 2 * slack, vt_sure, vt_maybe);
      }
    for (size_t i = 0; i < edges.size(); ++i)
      for (size_t j = i + 1; j < edges.size(); ++j) {
        const auto& e1 = edges[i];
        const auto& e2 = edges[j];
        if (e1[0] == e2[0] || e1[0] == e2[1] || e1[1] == e2[0] || e1[1] == e2[1]) continue;
        double rel = 0;
        for (int p : e1)
          for (int q : e2) rel = std::max(rel, (motion.row(p) - motion.row(q)).norm());
        const Vec3 a0 = x.row(e1[0]), a1 = x.row(e1[1]), b0 = x.row(e2[0]), b1 = x.row(e2[1]);
        // The boxes' gap is at most the distance: pairs beyond any reach here (< 14 mm) skip the search.
        const double gap =
            (b0.cwiseMin(b1) - a0.cwiseMax(a1)).cwiseMax(a0.cwiseMin(a1) - b0.cwiseMax(b1)).cwiseMax(0.0).norm();
        const double d = gap > 0.02 ? gap : segment_distance(a0, a1, b0, b1);
        count(box_gap({e1[0], e1[1]}, {e2[0], e2[1]}), d, thickness + rel + 2 * slack, ee_sure, ee_maybe);
      }
    sim::SelfCollision sc(m.F, nv);
    sc.detect(x, motion, slack, thickness, /*tangle_test=*/false);
    MESSAGE("vertex-triangle " << sc.num_vertex_triangle() << " (" << vt_sure << "-" << vt_maybe << "), edge-edge "
                               << sc.num_edge_edge() << " (" << ee_sure << "-" << ee_maybe << ")");
    CHECK(vt_sure > 1000);  // the layers are within reach of each other nearly everywhere
    CHECK(ee_sure > 1000);

    CHECK(sc.num_vertex_triangle() >= vt_sure);
    CHECK(sc.num_vertex_triangle() <= vt_maybe);
    CHECK(sc.num_edge_edge() >= ee_sure);
    CHECK(sc.num_edge_edge() <= ee_maybe);
  }
}

TEST_CASE("self-collision: cloth carried along together finds the pairs it finds at rest") {
  // The crumpled sheets of the test above, with their random motions, and again with 5 cm added
  // to every vertex's motion (the whole garment swept along by the body over the interval):
  // the relative motions are the same, so are the pairs, before and after a redetect (5% of the
  // vertices given new paths halfway through).
  const CrumpledSheets sheets(5);
  const auto& m = sheets.m;
  const int nv = static_cast<int>(m.V.rows());
  const double thickness = 0.005, slack = 0.001, half = 0.5;
  const Eigen::RowVector3d carried(0.03, -0.04, 0.0);
  const LeftPaths left(sheets.motion, half, 3);
  const std::vector<char>& moved = left.moved;
  const Points3& new_rest = left.rest;
  std::vector<std::array<int, 2>> vt[2][2], ee[2][2];  // [carried?][before / after the redetect]
  for (int k = 0; k < 2; ++k) {
    Points3 motion = sheets.motion, rest = new_rest;
    if (k == 1) motion.rowwise() += carried, rest.rowwise() += (1 - half) * carried;
    sim::SelfCollision sc(m.F, nv);
    sc.detect(sheets.x, motion, slack, thickness, /*tangle_test=*/false);
    vt[k][0] = sc.vertex_triangle_pairs(), ee[k][0] = sc.edge_edge_pairs();
    const Points3 start = sheets.x + half * motion;
    sc.redetect(start, start, rest, moved, half, slack, thickness);
    vt[k][1] = sc.vertex_triangle_pairs(), ee[k][1] = sc.edge_edge_pairs();
  }
  MESSAGE("vertex-triangle " << vt[0][0].size() << ", edge-edge " << ee[0][0].size());
  CHECK(vt[0][0].size() > 1000);
  CHECK(ee[0][0].size() > 1000);
  for (int i = 0; i < 2; ++i) {
    CHECK(vt[1][i] == vt[0][i]);
    CHECK(ee[1][i] == ee[0][i]);
  }
  CHECK(vt[0][1] != vt[0][0]);  // the redetect found other pairs for the moved vertices
}

TEST_CASE("self-collision: a detection that refits the last one's trees finds what a fresh detection finds") {
  // One detector detects the crumpled sheets of seed 5 (trees built), then those of seed 6
  // without the tangle test (trees refitted to the new boxes), then redetects 5% of the
  // vertices against the refitted trees; a fresh detector does the same on seed 6 only. A
  // refit that kept the old boxes would miss the pairs that only the new positions bring together.
  const CrumpledSheets first(5), second(6);
  const auto& m = first.m;
  const int nv = static_cast<int>(m.V.rows());
  const double thickness = 0.005, slack = 0.001, half = 0.5;
  const LeftPaths left(second.motion, half, 4);
  const std::vector<char>& moved = left.moved;
  const Points3& rest = left.rest;
  const Points3 start = second.x + half * second.motion;
  sim::SelfCollision refitted(m.F, nv), fresh(m.F, nv);
  refitted.detect(first.x, first.motion, slack, thickness, /*tangle_test=*/true);
  const auto vt_first = refitted.vertex_triangle_pairs();
  refitted.detect(second.x, second.motion, slack, thickness, /*tangle_test=*/false);
  fresh.detect(second.x, second.motion, slack, thickness, /*tangle_test=*/false);
  MESSAGE("vertex-triangle " << fresh.vertex_triangle_pairs().size() << ", edge-edge "
                             << fresh.edge_edge_pairs().size());
  CHECK(fresh.vertex_triangle_pairs().size() > 1000);
  CHECK(fresh.vertex_triangle_pairs() != vt_first);  // the two states have different pairs
  CHECK(refitted.vertex_triangle_pairs() == fresh.vertex_triangle_pairs());
  CHECK(refitted.edge_edge_pairs() == fresh.edge_edge_pairs());
  refitted.redetect(start, start, rest, moved, half, slack, thickness);
  fresh.redetect(start, start, rest, moved, half, slack, thickness);
  CHECK(refitted.num_redetections() == 1);
  CHECK(refitted.vertex_triangle_pairs() == fresh.vertex_triangle_pairs());
  CHECK(refitted.edge_edge_pairs() == fresh.edge_edge_pairs());
}

TEST_CASE("self-collision: bad inputs are refused with a message naming the problem") {
  const CrumpledSheets sheets(5);
  const auto& m = sheets.m;
  const int nv = static_cast<int>(m.V.rows());
  const Points3 &x = sheets.x, &motion = sheets.motion;
  const std::vector<char> none(nv, 0);
  using doctest::Contains;
  CHECK_THROWS_WITH_AS(sim::SelfCollision(m.F, nv - 1), Contains("faces index missing vertices"), gdsr::Error);
  sim::SelfCollision sc(m.F, nv);
  CHECK_THROWS_WITH_AS(sc.redetect(x, x, motion, none, 0.5, 0.001, 0.005), Contains("needs a detect first"),
                       gdsr::Error);
  CHECK_THROWS_WITH_AS(sc.detect(x.topRows(nv - 1), motion.topRows(nv - 1), 0.001, 0.005),
                       Contains("do not match the vertex count"), gdsr::Error);
  CHECK_THROWS_WITH_AS(sc.detect(x, motion, -0.001, 0.005), Contains("slack must be >= 0"), gdsr::Error);
  CHECK_THROWS_WITH_AS(sc.detect(x, motion, 0.001, std::nan("")), Contains("thickness > 0"), gdsr::Error);
  sc.detect(x, motion, 0.001, 0.005);
  for (const double elapsed : {-0.1, 1.5, std::nan("")})
    CHECK_THROWS_WITH_AS(sc.redetect(x, x, motion, none, elapsed, 0.001, 0.005), Contains("elapsed must be in [0, 1]"),
                         gdsr::Error);
  CHECK_THROWS_WITH_AS(sc.redetect(x, x, motion, std::vector<char>(nv - 1, 0), 0.5, 0.001, 0.005),
                       Contains("do not match the vertex count"), gdsr::Error);
  CHECK(sc.num_detections() == 1);  // only the good detect counted
}

TEST_CASE("self-collision: redetect finds the moved vertices' pairs again and keeps the others") {
  // The two crumpled sheets of the test above, moving; halfway through the interval 5% of the
  // vertices leave their paths (moved up to 4 mm, new motions). redetect must keep every pair
  // without a moved primitive as detect found it, and find every pair with one that detect
  // finds on the new paths (the header's rule), plus only pairs within reach (the boxes it keeps
  // of unmoved primitives cover the whole interval, not only the rest of it).
  const CrumpledSheets sheets(7);
  const auto& m = sheets.m;
  const Points3 &x = sheets.x, &motion = sheets.motion;
  const int nv = static_cast<int>(m.V.rows());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const double thickness = 0.005, slack = 0.001, half = 0.5;
  sim::SelfCollision sc(m.F, nv);
  sc.detect(x, motion, slack, thickness, /*tangle_test=*/false);
  const auto vt0 = sc.vertex_triangle_pairs();
  const auto ee0 = sc.edge_edge_pairs();

  Points3 start = x + half * motion, rest = (1 - half) * motion;
  std::vector<char> moved(nv, 0);
  sc.redetect(start, start, rest, moved, half, slack, thickness);  // none moved: nothing to do
  CHECK(sc.num_redetections() == 0);
  CHECK(sc.vertex_triangle_pairs() == vt0);
  CHECK(sc.edge_edge_pairs() == ee0);

  for (int v = 0; v < nv; ++v)
    if (u(rng) > 0.9) {
      moved[v] = 1;
      start.row(v) += 0.004 * Eigen::RowVector3d(u(rng), u(rng), u(rng));
      rest.row(v) = 0.002 * Eigen::RowVector3d(u(rng), u(rng), u(rng));
    }
  sc.redetect(start, start, rest, moved, half, slack, thickness);
  CHECK(sc.num_redetections() == 1);
  CHECK(sc.num_detections() == 1);
  sim::SelfCollision ref(m.F, nv);
  ref.detect(start, rest, slack, thickness, /*tangle_test=*/false);

  const auto& edges = sc.edges();
  auto face_moved = [&](int f) { return moved[m.F(f, 0)] || moved[m.F(f, 1)] || moved[m.F(f, 2)]; };
  auto edge_moved = [&](int e) { return moved[edges[e][0]] || moved[edges[e][1]]; };
  auto vt_moved = [&](const std::array<int, 2>& c) { return moved[c[0]] || face_moved(c[1]); };
  auto ee_moved = [&](const std::array<int, 2>& c) { return edge_moved(c[0]) || edge_moved(c[1]); };
  auto rel = [&](std::initializer_list<int> s, std::initializer_list<int> t) {
    double r = 0;
    for (int p : s)
      for (int q : t) r = std::max(r, (rest.row(p) - rest.row(q)).norm());
    return r;
  };
  // Pairs of one kind: the unmoved ones as detect found them; the moved ones a superset of the
  // reference's, each extra one within reach.
  auto check_kind = [&](const std::vector<std::array<int, 2>>& got, const std::vector<std::array<int, 2>>& before,
                        const std::vector<std::array<int, 2>>& want, auto is_moved, auto within_reach) {
    std::vector<std::array<int, 2>> got_kept, got_new, before_kept, want_new;
    for (const auto& c : got) (is_moved(c) ? got_new : got_kept).push_back(c);
    for (const auto& c : before)
      if (!is_moved(c)) before_kept.push_back(c);
    for (const auto& c : want)
      if (is_moved(c)) want_new.push_back(c);
    CHECK(std::is_sorted(got.begin(), got.end()));
    CHECK(got_kept == before_kept);
    CHECK(want_new.size() > 300);  // a fair share of the pairs is refreshed
    CHECK(std::includes(got_new.begin(), got_new.end(), want_new.begin(), want_new.end()));
    int extra = 0, beyond = 0;
    for (const auto& c : got_new)
      if (!std::binary_search(want_new.begin(), want_new.end(), c)) ++extra, beyond += !within_reach(c);
    MESSAGE(got_new.size() << " pairs refreshed, " << want_new.size() << " by detect on the new paths; " << extra
                           << " more, " << beyond << " of them beyond reach");
    CHECK(beyond == 0);
  };
  check_kind(sc.vertex_triangle_pairs(), vt0, ref.vertex_triangle_pairs(), vt_moved, [&](const std::array<int, 2>& c) {
    const int v = c[0], i = m.F(c[1], 0), j = m.F(c[1], 1), k = m.F(c[1], 2);
    const Vec3 p = start.row(v);
    const double d = (p - gdsr::closest_point_on_triangle(p, start.row(i), start.row(j), start.row(k)).point).norm();
    return d < (thickness + rel({v}, {i, j, k}) + 2 * slack) * (1 + 1e-9);
  });
  check_kind(sc.edge_edge_pairs(), ee0, ref.edge_edge_pairs(), ee_moved, [&](const std::array<int, 2>& c) {
    const auto &e1 = edges[c[0]], &e2 = edges[c[1]];
    const double d = segment_distance(start.row(e1[0]), start.row(e1[1]), start.row(e2[0]), start.row(e2[1]));
    return d < (thickness + rel({e1[0], e1[1]}, {e2[0], e2[1]}) + 2 * slack) * (1 + 1e-9);
  });
}

TEST_CASE("self-collision: detect and redetect find the same pairs on one thread as on two") {
  // The broad phase's collides are jobs shared by two threads when OpenMP allows two, and run in
  // turn when it allows one (ctest's OMP_NUM_THREADS=1): the pairs, their order, the crossings
  // found by the tangle test and the sides the pairs remember (seen through a projection pass)
  // must not depend on which.
  const CrumpledSheets sheets(5);
  const auto& m = sheets.m;
  const int nv = static_cast<int>(m.V.rows());
  const double thickness = 0.005, slack = 0.001;
  const Points3 start = sheets.x + 0.5 * sheets.motion, rest = 0.5 * sheets.motion;  // halfway, for redetect
  struct Found {
    std::vector<std::array<int, 2>> vt, ee, vt_re, ee_re;
    int crossing = 0;
    Points3 pushed;
  };
  auto found = [&](int threads) {
    const sim::OmpThreads scope(threads);
    REQUIRE(omp_get_max_threads() == threads);
    Found out;
    sim::SelfCollision sc(m.F, nv);
    sc.detect(sheets.x, sheets.motion, slack, thickness, /*tangle_test=*/true);
    out.vt = sc.vertex_triangle_pairs();
    out.ee = sc.edge_edge_pairs();
    out.crossing = sc.num_intersecting_pairs();
    std::vector<char> moved(nv, 0);
    for (int v = 0; v < nv; v += 7) moved[v] = 1;
    sc.redetect(start, start, rest, moved, 0.5, slack, thickness);
    out.vt_re = sc.vertex_triangle_pairs();
    out.ee_re = sc.edge_edge_pairs();
    out.pushed = start;
    sc.project(out.pushed, std::vector<double>(nv, 1.0), thickness);
    return out;
  };
  const Found one = found(1), two = found(2);
  MESSAGE(one.vt.size() << " vertex-triangle and " << one.ee.size() << " edge-edge pairs, " << one.crossing
                        << " crossings");
  CHECK(one.vt.size() > 1000);
  CHECK(one.ee.size() > 1000);
  CHECK(one.vt == two.vt);
  CHECK(one.ee == two.ee);
  CHECK(one.crossing == two.crossing);
  CHECK(one.vt_re == two.vt_re);
  CHECK(one.ee_re == two.ee_re);
  CHECK((one.pushed - start).cwiseAbs().maxCoeff() > 0);  // the pass pushed something
  CHECK((one.pushed - two.pushed).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("self-collision: redetecting the vertices that left their slack gives the full detection's simulation") {
  // The sheet dropped onto a clamped sheet (below), with SimParams::self_redetect on and off:
  // the same positions to the bit, in fewer full detections.
  std::vector<Points3> out[2];
  long long full[2] = {}, partial[2] = {};
  for (int k = 0; k < 2; ++k) {
    TwoSheetDrop d(0.03);
    d.p.self_redetect = k == 0;
    d.solver = std::make_unique<sim::ClothSolver>(d.g, gdsr::Faces(), Points3(), d.p);
    for (int t = 0; t < 20; ++t) {
      d.solver->step(Points3(), Points3(), 1.0 / 30);
      out[k].push_back(d.solver->positions());
    }
    full[k] = d.solver->num_self_detections();
    partial[k] = d.solver->num_self_redetections();
  }
  MESSAGE("detections " << full[0] << " + " << partial[0] << " redetections, against " << full[1]);
  CHECK(partial[0] > 20);
  CHECK(partial[1] == 0);
  CHECK(full[0] < full[1]);
  for (int t = 0; t < 20; ++t) {
    CAPTURE(t);
    CHECK(out[0][t] == out[1][t]);
  }
}

TEST_CASE("self-collision: the detector flags crossing triangles as tangled") {
  auto a = sheet(0.2, 0.05, 0.0);
  auto b = sheet(0.2, 0.05, 0.0);
  for (int v = 0; v < b.V.rows(); ++v) b.V.row(v) = Vec3(b.V(v, 0) + 0.013, b.V(v, 2) + 0.011, 0.007).transpose();
  const auto m = gdsr_test::merge_garment_meshes(a, b);
  sim::SelfCollision sc(m.F, static_cast<int>(m.V.rows()));
  sc.detect(m.V, Points3::Zero(m.V.rows(), 3), 0.0, 0.003);
  CHECK(sc.num_intersecting_pairs() > 0);
  CHECK(sc.num_tangled_vertices() > 0);
  // The flat sheet alone: nothing crosses, and nothing non-adjacent is within 3 mm.
  sim::SelfCollision s1(a.F, static_cast<int>(a.V.rows()));
  s1.detect(a.V, Points3::Zero(a.V.rows(), 3), 0.0, 0.003);
  CHECK(s1.num_intersecting_pairs() == 0);
  CHECK(s1.num_vertex_triangle() == 0);
}

TEST_CASE("self-collision: a sheet lying on two that cross is kept apart, and the crossing pair left free") {
  // Sheet a at y = 0 (20 mm), sheet b standing upright through it in the plane x = 1 mm: their
  // edges cross each other's faces along that line, and the vertices there are tangled. Sheet
  // c lies 3 mm above a beside the crossing (x 15-55 mm, 14 mm from b): its pairs with a's
  // faces at the crossing have a tangled vertex on a's side only. Those are still guarded (c is
  // pushed to the thickness), while a and b, tangled on both sides, are not pushed at all.
  // (Pairs tangled on either side were all freed before solver revision 31: c then lay on at
  // 3 mm, and on a kneel the tiers went through each other.)
  const double thickness = 0.005;
  auto a = sheet(0.2, 0.02, 0.0);
  auto b = sheet(0.2, 0.02, 0.0);
  for (int v = 0; v < b.V.rows(); ++v) b.V.row(v) = Vec3(0.001, b.V(v, 0) + 0.007, b.V(v, 2) + 0.003).transpose();
  auto c = sheet(0.04, 0.02, 0.003);
  for (int v = 0; v < c.V.rows(); ++v) c.V(v, 0) += 0.035;
  const auto ab = gdsr_test::merge_garment_meshes(a, b);
  const auto m = gdsr_test::merge_garment_meshes(ab, c);
  const int na = static_cast<int>(a.V.rows()), nab = static_cast<int>(ab.V.rows());
  const int nv = static_cast<int>(m.V.rows());
  sim::SelfCollision sc(m.F, nv);
  sc.detect(m.V, Points3::Zero(nv, 3), 0.0, thickness);
  REQUIRE(sc.num_intersecting_pairs() > 0);
  const std::vector<char>& tangled = sc.tangled();
  for (int v = nab; v < nv; ++v) REQUIRE(!tangled[v]);  // c crosses nothing
  // c's row nearest the crossing (x = 15 mm) lies over a's faces with tangled corners.
  std::vector<int> near_row;
  for (int v = nab; v < nv; ++v)
    if (std::abs(m.V(v, 0) - 0.015) < 1e-9) near_row.push_back(v);
  REQUIRE(near_row.size() == 3);
  bool over_tangled = false;
  for (int v = 0; v < na; ++v) over_tangled |= tangled[v] && std::abs(a.V(v, 0) - 0.02) < 1e-9;
  REQUIRE(over_tangled);
  const std::vector<double> winv(nv, 1.0);
  Points3 x = m.V;
  for (int pass = 0; pass < 20; ++pass) sc.project(x, winv, thickness);
  // b's vertices take part only in pairs with a at the crossing: not one moved.
  CHECK((x.block(na, 0, nab - na, 3) - m.V.block(na, 0, nab - na, 3)).cwiseAbs().maxCoeff() == 0);
  // c's vertices beside the crossing were pushed off a's surface to the thickness.
  const int fa = static_cast<int>(a.F.rows());
  for (int v : near_row) {
    double gap = 1e9;
    for (int f = 0; f < fa; ++f) {
      const Vec3 p = x.row(v), q0 = x.row(m.F(f, 0)), q1 = x.row(m.F(f, 1)), q2 = x.row(m.F(f, 2));
      gap = std::min(gap, (p - gdsr::closest_point_on_triangle(p, q0, q1, q2).point).norm());
    }
    CAPTURE(v);
    CHECK(x(v, 1) - m.V(v, 1) > 0.0005);
    CHECK(gap >= thickness - 1e-4);
  }
}

TEST_CASE("self-collision: contour minimisation pulls a bump back through the sheet it poked through") {
  // Sheet a (border fixed) at y = 0; sheet b 1 cm under it with a bump 2.5 cm high and 5 cm
  // across poking through a: one closed intersection contour. Only untangle() moves the
  // vertices (no stretch, no gravity): the contour shrinks until nothing crosses (CGAL).
  auto a = sheet(0.2, 0.02, 0.0);
  auto b = sheet(0.2, 0.02, -0.01);
  for (int v = 0; v < b.V.rows(); ++v) {
    const double r = std::hypot(b.V(v, 0) - 0.004, b.V(v, 2) + 0.003);
    if (r < 0.025) b.V(v, 1) += 0.025 * std::cos(r / 0.025 * 1.5707963);
  }
  const auto m = gdsr_test::merge_garment_meshes(a, b);
  const int na = static_cast<int>(a.V.rows()), nv = static_cast<int>(m.V.rows());
  std::vector<double> winv(nv, 1.0);
  for (int v = 0; v < na; ++v)
    if (std::max(std::abs(a.V(v, 0)), std::abs(a.V(v, 2))) > 0.1 - 1e-9) winv[v] = 0;
  Points3 x = m.V;
  const long pairs0 = gdsr::self_intersections(x, m.F).pairs;
  REQUIRE(pairs0 > 0);
  sim::SelfCollision sc(m.F, nv);
  const double step = 0.0005;
  int steps = 0, crossing = 1;
  for (; steps < 400 && crossing > 0; ++steps) {
    sc.detect(x, Points3::Zero(nv, 3), 0.0, 0.003);
    const Points3 before = x;
    crossing = sc.untangle(x, winv, step);
    CHECK((x - before).rowwise().norm().maxCoeff() <= step * (1 + 1e-9));
    for (int v = 0; v < nv; ++v)
      if (winv[v] == 0) CHECK((x.row(v) - before.row(v)).norm() == 0);
  }
  CAPTURE(steps);
  CHECK(crossing == 0);
  CHECK(gdsr::self_intersections(x, m.F).pairs == 0);
  // Without a tangle test there is nothing to untangle.
  sim::SelfCollision none(m.F, nv);
  Points3 y = m.V;
  CHECK(none.untangle(y, winv, step) == 0);
  CHECK((y - m.V).norm() == 0);
}

TEST_CASE("self-collision: a flap folded through a clamped sheet is pulled back out, not locked in") {
  // A 0.2 m sheet 2 cm above a clamped 0.4 m one, its last 5 cm folded straight down through
  // the lower sheet, without gravity (a fold is isometric: stretch has nothing to pull back,
  // and falling, the flap came out by itself). Freed of their self-contacts, the crossing
  // pairs stay crossed; contour minimisation pulls the flap out.
  const sim::Garment g = flap_through_sheet();
  REQUIRE(gdsr::self_intersections(g.mesh.V, g.mesh.F).pairs > 0);
  auto pairs_after = [&](double untangle_step) {
    sim::SimParams p;
    p.settle_frames = 0;
    p.untangle_step = untangle_step;
    p.gravity = Vec3::Zero();
    sim::ClothSolver solver(g, gdsr::Faces(), Points3(), p);
    for (int t = 0; t < 30; ++t) solver.step(Points3(), Points3(), 1.0 / 30);
    return gdsr::self_intersections(solver.positions(), g.mesh.F).pairs;
  };
  const long with = pairs_after(sim::SimParams().untangle_step), without = pairs_after(0.0);
  CAPTURE(with);
  CAPTURE(without);
  CHECK(with == 0);
  CHECK(without > 0);
}

TEST_CASE("self-collision: a guide that holds the flap folded through does not keep it there") {
  // The same flap, tracked (sim/cloth_tracking.hpp) by a guide that stays in the folded-through
  // shape, as an LR simulation whose fold the HR mesh crossed. The tangled cloth and three rings
  // of edges around it are not pulled, so untangling pulls the flap out; once it is free, the
  // self-contacts count the pull in each vertex's motion and hold it out. Measured: 0 pairs
  // after 30 frames; 46 when the tangled cloth is pulled too, 45 when the contacts do not count
  // the pull (a pair pushed across by it looked like an intersection that had slipped through).
  const sim::Garment g = flap_through_sheet();
  REQUIRE(gdsr::self_intersections(g.mesh.V, g.mesh.F).pairs > 0);
  const gdsr::Correspondence c = gdsr::compute_correspondence(g.mesh, g.mesh);
  const sim::GuideTracker tracker(c);
  const std::vector<Points3> body(30, Points3()), held(30, g.mesh.V);
  const sim::Guide guide{tracker, held};
  sim::SimParams p;
  p.settle_frames = 0;
  p.gravity = Vec3::Zero();
  REQUIRE(p.track_rate > 0);
  const auto frames = sim::simulate_frames(g, gdsr::Faces(), body, 30.0, p, {}, nullptr, &guide);
  const long pairs = gdsr::self_intersections(frames.back(), g.mesh.F).pairs;
  CAPTURE(pairs);
  CHECK(pairs == 0);
}

TEST_CASE("self-collision: a fine mesh gets a slack of 0.15 particle distances, detected less often") {
  // Two resting sheets without gravity: nothing leaves its path, so detections come only on the
  // schedule, one every self_detect_every substeps of the rule in effect.
  struct Case {
    double h, per_pd, slack;
    int every;
  };
  for (const Case& c : {Case{0.03, 0.15, 0.003, 4}, Case{0.02, 0.15, 0.003, 4}, Case{0.015, 0.15, 0.00225, 5},
                        Case{0.01, 0.15, 0.0015, 8}, Case{0.01, 10.0, 0.003, 4}}) {
    CAPTURE(c.h);
    CAPTURE(c.per_pd);
    int nl = 0;
    const sim::Garment g = two_sheets(c.h, nl);
    sim::SimParams p;
    p.settle_frames = 0;
    p.gravity = Vec3::Zero();
    p.self_slack_per_pd = c.per_pd;
    sim::ClothSolver solver(g, gdsr::Faces(), Points3(), p);
    CHECK(solver.params().self_slack == doctest::Approx(c.slack).epsilon(1e-12));
    CHECK(solver.params().self_detect_every == c.every);
    const int frames = 3;
    for (int t = 0; t < frames; ++t) solver.step(Points3(), Points3(), 1.0 / 30);
    CHECK(solver.num_self_detections() == (frames * p.substeps + c.every - 1) / c.every);
  }
}

TEST_CASE("self-collision: cloth falling together is detected on schedule, cloth falling onto still cloth more often") {
  // A 0.36 m sheet 1 m above a 0.5 m one, falling for 0.4 s (3.9 m/s, 0.78 m), both free, and
  // again with the lower sheet held still. The boxes are taken in a frame moving with the
  // cloth's mean motion and the detection interval shortens for the motion less the mean
  // (ClothSolver::detect_self_contacts): the sheets falling together (no relative motion at
  // all, as cloth carried by the body) are detected every self_detect_every substeps as at
  // rest; the falling sheet moves away from the mean of the two (63% of its speed at 30 mm),
  // so they are detected more often. Free fall follows the prediction exactly, so the slack
  // alone never triggers a detection.
  for (double h : {0.03, 0.015}) {
    CAPTURE(h);
    long long detections[2] = {};
    for (int held = 0; held < 2; ++held) {
      sim::Garment g;
      g.name = "falling sheets";
      g.particle_distance = h;
      g.mesh = gdsr_test::merge_garment_meshes(sheet(0.5, h, 0.0), sheet(0.36, h, 1.0));
      const int nl = static_cast<int>(sheet(0.5, h, 0.0).V.rows());
      if (held)
        for (int v = 0; v < nl; ++v) g.pinned.push_back(v);
      sim::SimParams p;
      p.settle_frames = 0;
      sim::ClothSolver solver(g, gdsr::Faces(), Points3(), p);
      const int frames = 12;
      for (int t = 0; t < frames; ++t) solver.step(Points3(), Points3(), 1.0 / 30);
      detections[held] = solver.num_self_detections();
      if (!held)
        CHECK(detections[0] ==
              (frames * p.substeps + solver.params().self_detect_every - 1) / solver.params().self_detect_every);
    }
    CAPTURE(detections[0]);
    CAPTURE(detections[1]);
    CHECK(detections[1] > detections[0] * 6 / 5);
  }
}

TEST_CASE("self-collision: a sheet dropped onto a clamped sheet lands on it at both resolutions") {
  for (double h : {0.03, 0.015}) {
    CAPTURE(h);
    // The upper sheet falls from 0.3 m and hits the lower one at ~2.4 m/s.
    TwoSheetDrop d(h);
    const int nl = d.nl;
    const sim::Garment& g = d.g;
    sim::ClothSolver& solver = *d.solver;
    int bad_frames = 0, below = 0;
    for (int t = 0; t < 24; ++t) {
      solver.step(Points3(), Points3(), 1.0 / 30);
      const auto& X = solver.positions();
      if (gdsr::self_intersections(X, g.mesh.F).pairs > 0) ++bad_frames;
    }
    // Every upper vertex above the lower sheet stays above it (the sheet sags only a little).
    const auto& X = solver.positions();
    double lower_max = -1e9;
    for (int v = 0; v < nl; ++v) lower_max = std::max(lower_max, X(v, 1));
    for (int v = nl; v < X.rows(); ++v)
      if (std::max(std::abs(X(v, 0)), std::abs(X(v, 2))) < 0.2 && X(v, 1) < lower_max - 0.05) ++below;
    CAPTURE(bad_frames);
    CAPTURE(below);
    CHECK(bad_frames == 0);
    CHECK(below == 0);
  }
}

TEST_CASE("self-collision: a cloth draped over a sphere folds without self-intersection") {
  const double r = 0.15;
  auto sphere = sim::make_sphere(Vec3(0, 0, 0), r, 24, 48);
  for (double h : {0.03, 0.015}) {
    CAPTURE(h);
    sim::Garment g;
    g.mesh = sheet(0.6, h, r + 0.02);
    g.name = "square";
    g.particle_distance = h;
    sim::SimParams p;
    p.settle_frames = 0;
    std::vector<Points3> frames(45, sphere.V);
    const auto out = sim::simulate_frames(g, sphere.F, frames, 30.0, p);
    int bad_frames = 0, worst = 0;
    for (size_t t = 0; t < out.size(); t += 2) {
      const int n = static_cast<int>(gdsr::self_intersections(out[t], g.mesh.F).pairs);
      bad_frames += n > 0;
      worst = std::max(worst, n);
    }
    CAPTURE(bad_frames);
    CAPTURE(worst);
    CHECK(bad_frames == 0);
    // It did fold: the rim hangs well below the top.
    CHECK(out.back().col(1).minCoeff() < -0.05);
  }
}

TEST_CASE("self-collision: a vertex found beyond its reach on the wrong side is freed, one just across is pushed back") {
  // One triangle in the plane y = 0 and a lone vertex 2 mm above its middle (a fourth
  // triangle corner far away keeps the vertex from being adjacent to anything).
  const gdsr::Faces F = (gdsr::Faces(2, 3) << 0, 1, 2, 3, 4, 5).finished();
  Points3 x(6, 3);
  x << 0, 0, 0, 0.1, 0, 0, 0, 0, 0.1,  // the triangle
      0.02, 0.002, 0.02, 1, 1, 1, 1.01, 1, 1;  // vertex 3, with a far-away sliver for a face
  const std::vector<double> winv = {0, 0, 0, 1, 1, 1};
  const double thickness = 0.003, slack = 0.001;
  sim::SelfCollision sc(F, 6);
  sc.detect(x, Points3::Zero(6, 3), slack, thickness);  // at rest: reach = 3 + 0 + 2 mm
  REQUIRE(sc.num_vertex_triangle() == 1);
  // Just across (1 mm below): an intersection the motion explains, pushed back above.
  Points3 y = x;
  y(3, 1) = -0.001;
  CHECK(sc.project(y, winv, thickness) >= 1);
  CHECK(sc.num_crossed_pushed() == 1);  // the solver's cue to look for intersections again
  CHECK(y(3, 1) == doctest::Approx(thickness).epsilon(1e-9));
  // 4 cm below, far beyond the pair's reach: an intersection that slipped through elsewhere.
  // Pushing it 4 cm back up tore the cloth into spikes; it is left to untangle.
  Points3 z = x;
  z(3, 1) = -0.04;
  CHECK(sc.project(z, winv, thickness) == 0);
  CHECK(sc.num_crossed_pushed() == 0);
  CHECK(z(3, 1) == -0.04);
}

TEST_CASE("self-collision: a push back across that would make the faces intersect is refused, the side corrected") {
  // A small fan of four triangles around vertex 3, fixed at its rim 2 mm above a fixed
  // triangle, its centre free. Detected while the centre was pressed 1 mm through the triangle
  // (no tangle test, as the solver's detections within a frame), the pair remembers the wrong
  // side; then the centre is back above (a body contact undid the press) and nothing
  // intersects. Pushed back to its remembered side, the centre would pull the fan's edges
  // through the triangle: with set_refuse_crossing_pushes the push is refused, the side taken
  // from the geometry, and the next pass keeps the centre a thickness above; without (the
  // solver's default), it goes 3 mm below.
  const gdsr::Faces F = (gdsr::Faces(5, 3) << 0, 1, 2, 3, 4, 6, 3, 6, 5, 3, 5, 7, 3, 7, 4).finished();
  Points3 x(8, 3);
  x << 0, 0, 0, 0.1, 0, 0, 0, 0, 0.1,                                              // the triangle
      0.03, 0.001, 0.03,                                                           // the fan's centre
      0.01, 0.002, 0.03, 0.05, 0.002, 0.03, 0.03, 0.002, 0.01, 0.03, 0.002, 0.05;  // its rim
  const std::vector<double> winv = {0, 0, 0, 1, 0, 0, 0, 0};
  const double thickness = 0.003, slack = 0.001;
  Points3 pressed = x;
  pressed(3, 1) = -0.001;
  REQUIRE(gdsr::self_intersections(pressed, F).pairs > 0);
  REQUIRE(gdsr::self_intersections(x, F).pairs == 0);
  const auto pushing = detected_pressed(F, pressed, slack, thickness, false);
  Points3 w = x;
  pushing->project(w, winv, thickness);
  CHECK(pushing->num_crossed_pushed() == 1);
  CHECK(w(3, 1) == doctest::Approx(-thickness).epsilon(1e-9));
  CHECK(gdsr::self_intersections(w, F).pairs > 0);
  const auto sc = detected_pressed(F, pressed, slack, thickness, true);
  REQUIRE(sc->num_tangled_vertices() == 0);
  Points3 y = x;
  sc->project(y, winv, thickness);
  CHECK(sc->num_sides_corrected() == 1);
  CHECK(sc->num_crossed_pushed() == 0);
  CHECK(y(3, 1) == 0.001);  // not moved by the refused push
  sc->project(y, winv, thickness);
  CHECK(sc->num_sides_corrected() == 0);
  CHECK(y(3, 1) == doctest::Approx(thickness).epsilon(1e-9));
  CHECK(gdsr::self_intersections(y, F).pairs == 0);
  // Told which vertices body contacts moved this iteration, only their pairs' pushes are refused.
  for (const char centre_moved : {0, 1}) {
    CAPTURE(static_cast<int>(centre_moved));
    std::vector<char> body_moved(8, 0);
    body_moved[3] = centre_moved;
    const auto told = detected_pressed(F, pressed, slack, thickness, true);
    told->set_body_moved(&body_moved);
    Points3 u = x;
    told->project(u, winv, thickness);
    CHECK(told->num_sides_corrected() == centre_moved);
    CHECK(u(3, 1) == (centre_moved ? 0.001 : doctest::Approx(-thickness).epsilon(1e-9)));
  }
  // A pair that is still crossing is pushed back as before (the push undoes the crossing).
  Points3 z = pressed;
  sim::SelfCollision again(F, 8);
  again.set_refuse_crossing_pushes(true);
  again.detect(x, Points3::Zero(8, 3), slack, thickness);
  again.project(z, winv, thickness);
  CHECK(again.num_sides_corrected() == 0);
  CHECK(again.num_crossed_pushed() == 1);
  CHECK(z(3, 1) == doctest::Approx(thickness).epsilon(1e-9));
}

TEST_CASE("self-collision: an edge pair pushed back across into an intersection is refused, the side corrected") {
  // Two upright triangles whose free edges cross at right angles: the upper one's bottom edge
  // (along x, free) and the lower one's top edge (along z, fixed). Detected while the upper
  // edge was pressed 1 mm below the lower one (the triangles intersect), then back 1 mm above
  // (they do not): with set_refuse_crossing_pushes the push back to the remembered side below
  // is refused, and the edge is kept a thickness above.
  const gdsr::Faces F = (gdsr::Faces(2, 3) << 0, 1, 2, 3, 4, 5).finished();
  Points3 x(6, 3);
  x << -0.05, 0.001, 0, 0.05, 0.001, 0, 0, 0.1, 0,  // upper, in the plane z = 0
      0, 0, -0.05, 0, 0, 0.05, 0, -0.1, 0;          // lower, in the plane x = 0
  const std::vector<double> winv = {1, 1, 0, 0, 0, 0};
  const double thickness = 0.003, slack = 0.001;
  Points3 pressed = x;
  pressed(0, 1) = pressed(1, 1) = -0.001;
  REQUIRE(gdsr::self_intersections(pressed, F).pairs > 0);
  REQUIRE(gdsr::self_intersections(x, F).pairs == 0);
  const auto sc = detected_pressed(F, pressed, slack, thickness, true);
  REQUIRE(sc->num_edge_edge() == 1);
  Points3 y = x;
  sc->project(y, winv, thickness);
  CHECK(sc->num_sides_corrected() == 1);
  CHECK(y(0, 1) == 0.001);
  sc->project(y, winv, thickness);
  CHECK(y(0, 1) == doctest::Approx(thickness).epsilon(1e-9));
  CHECK(y(1, 1) == y(0, 1));
  CHECK(gdsr::self_intersections(y, F).pairs == 0);
}

TEST_CASE("self-collision: a pair found deep across, within its reach, is pushed back by at most the cap per pass") {
  // A triangle and a lone vertex as above (a larger triangle: no corner within the vertex's
  // reach), detected while the vertex moves 5 cm down (reach 3 + 50 + 2 mm): found 3 cm
  // across, it was pushed all the way back, 33 mm in one pass; with the solver's cap
  // (SimParams::self_crossed_push, one thickness) it moves 3 mm a pass. A pair just too close
  // is pushed as before: the cap limits only crossed pairs.
  const gdsr::Faces F = (gdsr::Faces(2, 3) << 0, 1, 2, 3, 4, 5).finished();
  Points3 x(6, 3);
  x << 0, 0, 0, 0.3, 0, 0, 0, 0, 0.3, 0.08, 0.002, 0.08, 1, 1, 1, 1.01, 1, 1;
  Points3 motion = Points3::Zero(6, 3);
  motion(3, 1) = -0.05;
  const std::vector<double> winv = {0, 0, 0, 1, 1, 1};
  const double thickness = 0.003, slack = 0.001;
  sim::SelfCollision sc(F, 6);
  sc.detect(x, motion, slack, thickness);
  REQUIRE(sc.num_vertex_triangle() == 1);
  Points3 all = x, capped = x;
  all(3, 1) = capped(3, 1) = -0.03;
  CHECK(sc.project(all, winv, thickness) == 1);
  CHECK(all(3, 1) == doctest::Approx(thickness).epsilon(1e-9));
  CHECK(sc.project(capped, winv, thickness, thickness) == 1);
  CHECK(capped(3, 1) == doctest::Approx(-0.03 + thickness).epsilon(1e-9));
  int passes = 1;  // 3 cm across at 3 mm a pass: back at the thickness on its side after 11 passes
  for (; passes < 20 && capped(3, 1) < thickness - 1e-12; ++passes) sc.project(capped, winv, thickness, thickness);
  CHECK(passes == 11);
  CHECK(capped(3, 1) == doctest::Approx(thickness).epsilon(1e-9));
  Points3 close = x;  // 1 mm above: pushed to the thickness in one pass, capped or not
  close(3, 1) = 0.001;
  CHECK(sc.project(close, winv, thickness, thickness) == 1);
  CHECK(sc.num_crossed_pushed() == 0);  // too close, not crossed
  CHECK(close(3, 1) == doctest::Approx(thickness).epsilon(1e-9));
}

TEST_CASE(
    "self-collision: with a mass floor, a pair whose only free vertex carries little of the contact point moves it a "
    "little") {
  // A pinned vertex 2 mm above a triangle near its corner 0 (barycentric 0.9, 0.05, 0.05), the
  // triangle pinned but for corner 2: 1 mm too close. Solved exactly, corner 2 moves 1 mm over
  // its weight 0.05, 20 mm; with the generalised inverse mass's floor at a quarter of the largest
  // vertex's (the solver's with pins a hand may press, SimParams::pin_yield_rate) 0.05 x 1 mm /
  // 0.25 = 0.2 mm. A pressed pin threw a vertex of the 10 mm pleated skirt 1.7 m in one pass.
  const gdsr::Faces F = (gdsr::Faces(2, 3) << 0, 1, 2, 3, 4, 5).finished();
  Points3 x(6, 3);
  x << 0, 0, 0, 0.1, 0, 0, 0, 0, 0.1, 0.005, 0.002, 0.005, 1, 1, 1, 1.01, 1, 1;
  const std::vector<double> winv = {0, 0, 1, 0, 1, 1};
  const double thickness = 0.003;
  sim::SelfCollision sc(F, 6);
  sc.detect(x, Points3::Zero(6, 3), 0.001, thickness);
  REQUIRE(sc.num_vertex_triangle() == 1);
  Points3 exact = x, floored = x;
  CHECK(sc.project(exact, winv, thickness) == 1);
  CHECK((exact.row(2) - x.row(2)).norm() == doctest::Approx(0.001 / 0.05).epsilon(1e-6));
  CHECK(sc.project(floored, winv, thickness, thickness, 0.25) == 1);
  CHECK((floored.row(2) - x.row(2)).norm() == doctest::Approx(0.05 * 0.001 / 0.25).epsilon(1e-6));
  CHECK((floored.topRows(2) - x.topRows(2)).norm() == 0);
  CHECK((floored.row(3) - x.row(3)).norm() == 0);
}

TEST_CASE("self-collision: the projection on two threads gives the one-thread passes bit for bit") {
  // The crumpled sheets (seed 8) detected 5 mm thick, then pressed together (the upper sheet
  // 2 mm lower): most pairs are too close, many are pushed, and the pushes move vertices that
  // later pairs read. Every 17th vertex pinned (inverse mass 0), the crossed-push cap and the mass
  // floor on, as the solver calls it. Five passes on two threads (the first phase evaluates
  // every pair at the pass's starting positions, the second redoes the pairs a push has
  // touched) against five on one: the same positions bit for bit, the same counts pushed (and
  // pushed back across).
  const CrumpledSheets sheets(8);
  const auto& m = sheets.m;
  const int nv = static_cast<int>(m.V.rows());
  const double thickness = 0.005, slack = 0.001;
  std::vector<double> winv(nv, 1.0);
  for (int v = 0; v < nv; v += 17) winv[v] = 0;
  Points3 pressed = sheets.x;
  for (int v = nv / 2; v < nv; ++v) pressed(v, 1) -= 0.002;  // the upper sheet: the second half
  bool refuse = false;
  auto passes = [&](int threads, std::vector<int>& pushed, std::vector<int>& crossed, std::vector<int>& corrected) {
    const sim::OmpThreads scope(threads);
    sim::SelfCollision sc(m.F, nv);
    sc.set_refuse_crossing_pushes(refuse);
    sc.detect(sheets.x, sheets.motion, slack, thickness);
    REQUIRE(static_cast<size_t>(sc.num_vertex_triangle() + sc.num_edge_edge()) >=
            sim::SelfCollision::kTwoThreadProjectPairs);
    Points3 y = pressed;
    for (int k = 0; k < 5; ++k) {
      pushed.push_back(sc.project(y, winv, thickness, thickness, 0.25));
      crossed.push_back(sc.num_crossed_pushed());
      corrected.push_back(sc.num_sides_corrected());
    }
    return y;
  };
  std::vector<int> pushed1, pushed2, crossed1, crossed2, corrected1, corrected2;
  const Points3 one = passes(1, pushed1, crossed1, corrected1), two = passes(2, pushed2, crossed2, corrected2);
  MESSAGE("pairs pushed per pass: " << pushed1[0] << " " << pushed1[1] << " " << pushed1[4] << ", back across "
                                    << crossed1[0] << " " << crossed1[1] << " " << crossed1[4]);
  CHECK(pushed1[0] > 300);
  CHECK(pushed1[4] > 0);  // still pushing: each pass starts from the last one's moves
  CHECK((one - pressed).cwiseAbs().maxCoeff() > 1e-3);
  CHECK(pushed2 == pushed1);
  CHECK(crossed1[0] > 0);  // pressed 2 mm, some pairs are found across
  CHECK(crossed2 == crossed1);
  CHECK(corrected2 == corrected1);
  CHECK((two - one).cwiseAbs().maxCoeff() == 0.0);
  // The same with pushes that would make faces intersect refused (SimParams::self_refuse_crossing_push).
  refuse = true;
  std::vector<int> pushed3, pushed4, crossed3, crossed4, corrected3, corrected4;
  const Points3 three = passes(1, pushed3, crossed3, corrected3), four = passes(2, pushed4, crossed4, corrected4);
  int refused = 0;
  for (int n : corrected3) refused += n;
  MESSAGE("pushes refused over the five passes: " << refused);
  CHECK(refused > 0);
  CHECK(pushed4 == pushed3);
  CHECK(crossed4 == crossed3);
  CHECK(corrected4 == corrected3);
  CHECK((four - three).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("self-collision: resting layers are kept the larger of the thickness and a sixth of the particle distance apart") {
  // The dropped sheet of the test above, 1.5 s later at rest on the clamped one: the gap from
  // each upper vertex over the middle to the nearest lower triangle (brute force), median.
  // (particle distance, thickness): a sixth of 30 mm over a 3 mm thickness; the default 5 mm over a sixth of 15 mm.
  for (const auto& [h, thickness] : {std::pair{0.03, 0.003}, std::pair{0.015, -1.0}}) {
    CAPTURE(h);
    CAPTURE(thickness);
    TwoSheetDrop d(h, thickness);
    const int nl = d.nl;
    for (int t = 0; t < 45; ++t) d.solver->step(Points3(), Points3(), 1.0 / 30);
    const auto& X = d.solver->positions();
    const sim::Garment& g = d.g;
    const sim::SimParams& p = d.p;
    std::vector<double> gaps;
    for (int v = nl; v < X.rows(); ++v) {
      if (std::max(std::abs(X(v, 0)), std::abs(X(v, 2))) > 0.12) continue;
      double d = 1e9;
      for (int f = 0; f < g.mesh.F.rows(); ++f) {
        if (g.mesh.F(f, 0) >= nl) continue;  // upper sheet's own faces
        const Vec3 q = X.row(v);
        const auto cp = gdsr::closest_point_on_triangle(q, X.row(g.mesh.F(f, 0)), X.row(g.mesh.F(f, 1)),
                                                        X.row(g.mesh.F(f, 2)));
        d = std::min(d, (q - cp.point).norm());
      }
      gaps.push_back(d);
    }
    REQUIRE(gaps.size() > 5);
    std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
    const double want = std::max(p.self_thickness, h * p.self_thickness_per_pd);
    CAPTURE(want);
    CHECK(gaps[gaps.size() / 2] == doctest::Approx(want).epsilon(0.1));
  }
}

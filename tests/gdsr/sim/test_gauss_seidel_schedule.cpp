// GaussSeidelSchedule: a Gauss-Seidel pass run on two threads must give the sequential pass's
// result bit for bit. The pass here is the cloth solver's: edge-length projections, each
// reading the positions the earlier ones wrote, on a sheet whose edges are sorted by vertex,
// with a few long "seam" edges joining far-apart vertex numbers (as a garment's panels are).
#include <doctest/doctest.h>

#include "tests/support/omp_threads.hpp"

#include "gdsr/sim/gauss_seidel_schedule.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/mesh.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <vector>

using gdsr::Points3;

namespace {

struct Sheet {
  int nv;
  std::vector<sim::GaussSeidelSchedule::Item> edges;  // sorted (i < j), two -1s
  std::vector<double> rest;
  Points3 x;
};

// An n x n grid, triangulated, plus `seams` random edges between far-apart vertices; positions
// jittered so that every edge is off its rest length.
Sheet make_sheet(int n, int seams, unsigned seed) {
  std::mt19937 rng(seed);
  std::set<sim::GaussSeidelSchedule::Item> e;
  auto add = [&](int a, int b) { e.insert({std::min(a, b), std::max(a, b), -1, -1}); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int v = i * n + j;
      if (j + 1 < n) add(v, v + 1);
      if (i + 1 < n) add(v, v + n);
      if (i + 1 < n && j + 1 < n) add(v, v + n + 1);
    }
  std::uniform_int_distribution<int> any(0, n * n - 1);
  for (int k = 0; k < seams; ++k) {
    const int a = any(rng), b = any(rng);
    if (a != b) add(a, b);
  }
  Sheet s{n * n, {e.begin(), e.end()}, {}, Points3(n * n, 3)};
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (int v = 0; v < s.nv; ++v) s.x.row(v) << v % n + jitter(rng), v / n + jitter(rng), jitter(rng);
  for (size_t k = 0; k < s.edges.size(); ++k) s.rest.push_back(1 + 0.5 * jitter(rng));
  return s;
}

// One projection of edge c (equal weights): the cloth solver's stretch step without compliance.
void project_edge(const Sheet& s, int c, Points3& x) {
  const int i = s.edges[c][0], j = s.edges[c][1];
  Eigen::RowVector3d d = x.row(i) - x.row(j);
  const double len = d.norm();
  if (len < 1e-12) return;
  const double C = 0.5 * (len - s.rest[c]) / len;
  x.row(i) -= C * d;
  x.row(j) += C * d;
}

Points3 sequential(const Sheet& s, int passes) {
  Points3 x = s.x;
  for (int p = 0; p < passes; ++p)
    for (int c = 0; c < static_cast<int>(s.edges.size()); ++c) project_edge(s, c, x);
  return x;
}

}  // namespace

TEST_CASE("gauss-seidel schedule: two threads give the sequential pass bit for bit, seams and all") {
  const sim::TwoOmpThreads threads;
  for (int seams : {0, 40, 400}) {
    CAPTURE(seams);
    const Sheet s = make_sheet(80, seams, 3 + seams);
    sim::GaussSeidelSchedule schedule;
    schedule.plan(s.edges, s.nv);
    REQUIRE(schedule.size() == static_cast<int>(s.edges.size()));
    CHECK(schedule.levels() < schedule.size() / 10);   // mostly independent work: the reason for it
    CHECK(schedule.waits(0) + schedule.waits(1) > 0);  // the lists do depend on each other
    Points3 x = s.x;
    for (int p = 0; p < 4; ++p) schedule.run([&](int c, int) { project_edge(s, c, x); });
    const Points3 want = sequential(s, 4);
    CHECK((x - want).cwiseAbs().maxCoeff() == 0.0);
    CHECK((want - s.x).cwiseAbs().maxCoeff() > 0.01);  // the passes did move the sheet
    // Slots: each item gets its own, the one slot() names.
    std::vector<int> slot_of(s.edges.size(), -1), taken(s.edges.size(), 0);
    schedule.run([&](int c, int slot) { slot_of[c] = slot; });
    bool named = true;
    for (size_t c = 0; c < s.edges.size(); ++c) {
      named = named && slot_of[c] == schedule.slot(static_cast<int>(c));
      if (slot_of[c] >= 0) ++taken[slot_of[c]];
    }
    CHECK(named);
    CHECK(std::all_of(taken.begin(), taken.end(), [](int n) { return n == 1; }));
  }
}

TEST_CASE("gauss-seidel schedule: four-vertex items (contact pairs) give the sequential pass bit for bit") {
  const sim::TwoOmpThreads threads;
  // Vertex-triangle pairs as the self-contact projection has them: sorted by the vertex, each
  // against a triangle of three vertices near it; a step pulls the four a length-dependent way.
  const Sheet s = make_sheet(60, 0, 9);
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> near(-130, 130);
  std::vector<sim::GaussSeidelSchedule::Item> pairs;
  for (int v = 0; v < s.nv; ++v)
    for (int r = 0; r < 3; ++r) {
      const int f = std::clamp(v + near(rng), 0, s.nv - 3);
      if (v < f || v > f + 2) pairs.push_back({v, f, f + 1, f + 2});
    }
  auto step = [&](const sim::GaussSeidelSchedule::Item& p, Points3& x) {
    const Eigen::RowVector3d c = (x.row(p[1]) + x.row(p[2]) + x.row(p[3])) / 3;
    const Eigen::RowVector3d d = x.row(p[0]) - c;
    const double k = 0.1 * std::tanh(d.norm());
    x.row(p[0]) -= k * d;
    for (int i = 1; i < 4; ++i) x.row(p[i]) += (k / 3) * d;
  };
  sim::GaussSeidelSchedule schedule;
  schedule.plan(pairs, s.nv);
  Points3 x = s.x, want = s.x;
  for (int pass = 0; pass < 2; ++pass) {
    schedule.run([&](int k, int) { step(pairs[k], x); });
    for (const auto& p : pairs) step(p, want);
  }
  CHECK(schedule.waits(0) + schedule.waits(1) > 0);
  CHECK((x - want).cwiseAbs().maxCoeff() == 0.0);
  CHECK((want - s.x).cwiseAbs().maxCoeff() > 0.01);
}

TEST_CASE("gauss-seidel schedule: on one thread (a nested region) it runs the items in order") {
  const sim::TwoOmpThreads threads;
  const Sheet s = make_sheet(30, 10, 5);
  sim::GaussSeidelSchedule schedule;
  schedule.plan(s.edges, s.nv);
  Points3 x = s.x;
  std::vector<int> seen;
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(1);
#pragma omp parallel num_threads(2)
  {
    if (omp_get_thread_num() == 0)
      schedule.run([&](int c, int) {
        seen.push_back(c);
        project_edge(s, c, x);
      });
  }
  omp_set_max_active_levels(levels);
  std::vector<int> order(s.edges.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  CHECK(seen == order);
  CHECK((x - sequential(s, 1)).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE(
    "gauss-seidel schedule: a chain has one level per item, an empty list runs nothing, bad vertices are refused") {
  const sim::TwoOmpThreads threads;
  std::vector<sim::GaussSeidelSchedule::Item> chain;
  for (int v = 0; v + 1 < 50; ++v) chain.push_back({v, v + 1, -1, -1});
  sim::GaussSeidelSchedule schedule;
  schedule.plan(chain, 50);
  CHECK(schedule.levels() == 49);
  std::vector<int> count(49, 0);
  schedule.run([&](int c, int) { ++count[c]; });  // each item once, though every one waits on the last
  CHECK(std::all_of(count.begin(), count.end(), [](int n) { return n == 1; }));

  schedule.plan({}, 10);
  CHECK(schedule.size() == 0);
  schedule.run([&](int, int) { FAIL("no items to run"); });
  CHECK_THROWS_WITH(schedule.plan({{0, 10, -1, -1}}, 10), doctest::Contains("item vertex 10 out of range"));
}

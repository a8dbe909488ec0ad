// The cloth solver's Gauss-Seidel work on one thread and on two, with the same result: one
// stretch pass over the edges of the 10 mm long-sleeve t-shirt (15.2k vertices, 45k edges on
// the CMU 01_01 body), in edge order on one thread and by GaussSeidelSchedule on two; and the
// implicit bending step (ImplicitBending::solve: Jacobi sweeps or the factorisation's
// substitutions) on one thread and two; one self-contact pass (SelfCollision::project) on one thread and two. The time
// is per pass or per solve. Counters: edges, levels, and `same` = 1 when the two-thread positions
// equal the one-thread ones bit for bit after every pass timed.
// Run with nothing else on the machine: a thread that waits for the other one's edges loses
// the gain when the other is descheduled.
#include <benchmark/benchmark.h>

#include "gdsr/body/body.hpp"
#include "gdsr/sim/cloth_bending_solve.hpp"
#include "gdsr/sim/cloth_self_collision.hpp"
#include "gdsr/sim/gauss_seidel_schedule.hpp"
#include "gdsr/sim/garments.hpp"
#include "tests/support/crumpled_sheets.hpp"

#include <omp.h>

#include <map>
#include <memory>
#include <random>
#include <set>

namespace {

struct Shirt {
  sim::Garment g;
  std::vector<sim::GaussSeidelSchedule::Item> edges;  // sorted (i < j), as ClothSolver has them
  std::vector<double> rest;
  gdsr::Points3 x;  // the placement, every vertex moved by up to 1 mm
};

const Shirt& shirt() {
  static const Shirt s = [] {
    gdsr::BodyOptions o;
    o.rest_arm_drop_degrees = sim::rest_arm_drop_degrees("tshirt");
    const gdsr::TriMesh rest = gdsr::load_body_sequence("/usr/share/assimp/models/BVH/01_01.bvh", o).rest_mesh();
    Shirt sh{sim::make_garment("tshirt", 0.010, rest), {}, {}, {}};
    const auto& m = sh.g.mesh;
    std::set<sim::GaussSeidelSchedule::Item> e;
    for (int f = 0; f < m.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = m.F(f, k), b = m.F(f, (k + 1) % 3);
        e.insert({std::min(a, b), std::max(a, b), -1, -1});
      }
    sh.edges.assign(e.begin(), e.end());
    for (const auto& ed : sh.edges) sh.rest.push_back((m.V.row(ed[0]) - m.V.row(ed[1])).norm());
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
    sh.x = m.V;
    for (int v = 0; v < sh.x.rows(); ++v) sh.x.row(v) += Eigen::RowVector3d(jitter(rng), jitter(rng), jitter(rng));
    return sh;
  }();
  return s;
}

// The solver's stretch step of one edge (equal masses, compliance 1e-9 m/N over h^2).
void stretch(const Shirt& s, int c, double& lambda, gdsr::Points3& x) {
  const int i = s.edges[c][0], j = s.edges[c][1];
  constexpr double w = 1 / 2.5e-4, at = 1e-9 * 3600 * 400;  // 0.25 g per vertex; h = 1/600 s
  Eigen::RowVector3d d = x.row(i) - x.row(j);
  const double len = d.norm();
  if (len < 1e-12) return;
  d /= len;
  const double dl = (-(len - s.rest[c]) - at * lambda) / (2 * w + at);
  lambda += dl;
  x.row(i) += (w * dl) * d;
  x.row(j) -= (w * dl) * d;
}

void BM_StretchPass(benchmark::State& st) {
  const Shirt& s = shirt();
  const int ne = static_cast<int>(s.edges.size());
  sim::GaussSeidelSchedule schedule;
  schedule.plan(s.edges, static_cast<int>(s.x.rows()));
  const bool two = st.range(0) == 2;
  gdsr::Points3 x = s.x, ref = s.x;
  std::vector<double> lambda(ne, 0.0), lambda_ref(ne, 0.0);
  int passes = 0;
  for (auto _ : st) {
    if (two)
      schedule.run([&](int c, int) { stretch(s, c, lambda[c], x); });
    else
      for (int c = 0; c < ne; ++c) stretch(s, c, lambda[c], x);
    ++passes;
  }
  if (two)  // the one-thread passes, untimed, to compare
    for (int p = 0; p < passes; ++p)
      for (int c = 0; c < ne; ++c) stretch(s, c, lambda_ref[c], ref);
  st.counters["edges"] = ne;
  st.counters["levels"] = schedule.levels();
  st.counters["same"] = two ? ((x - ref).cwiseAbs().maxCoeff() == 0.0) : 1.0;
}
BENCHMARK(BM_StretchPass)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();

// The 10 mm t-shirt's hinges as the cloth solver makes them (cotangent weights of the pattern's
// triangles, stiffness = the solver's default modulus 2e-6 N m over the two faces' area; masses
// of the default 0.08 kg/m^2), its pinned vertices fixed. Args: threads, substeps per 1/30 s
// frame (h), method (0: the solver's choice, Jacobi where the mass dominates; 1: always the
// factorisation). Counters: ratio (ImplicitBending::dominance_ratio: <= 0.75 takes Jacobi),
// iterations (Jacobi sweeps of a solve, 0 for the factorisation) and err_m, the largest
// coordinate difference between the two methods' results, in metres.
struct Hinges {
  std::vector<sim::BendStencil> bends;
  std::vector<double> mass;
  std::vector<char> fixed;
};
const Hinges& hinges() {
  static const Hinges hg = [] {
    const Shirt& s = shirt();
    const auto& m = s.g.mesh;
    const int nv = static_cast<int>(m.V.rows());
    Hinges h{{}, std::vector<double>(nv, 0.0), std::vector<char>(nv, 0)};
    auto uv = [&](int f, int vert) {  // the pattern (UV, metres) position of a face's corner
      for (int k = 0; k < 3; ++k)
        if (m.F(f, k) == vert) return Eigen::RowVector2d(m.UV.row(m.FUV(f, k)));
      return Eigen::RowVector2d(0, 0);
    };
    auto area = [&](int f) {
      const Eigen::RowVector2d a = uv(f, m.F(f, 1)) - uv(f, m.F(f, 0)), b = uv(f, m.F(f, 2)) - uv(f, m.F(f, 0));
      return 0.5 * std::abs(a.x() * b.y() - a.y() * b.x());
    };
    auto cot = [&](int f, int o, int a, int b) {  // cotangent of face f's angle at o, between a and b
      const Eigen::RowVector2d u = uv(f, a) - uv(f, o), w = uv(f, b) - uv(f, o);
      return u.dot(w) / std::abs(u.x() * w.y() - u.y() * w.x());
    };
    std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> faces;  // edge -> (face, opposite vertex)
    for (int f = 0; f < m.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = m.F(f, k), b = m.F(f, (k + 1) % 3), o = m.F(f, (k + 2) % 3);
        faces[{std::min(a, b), std::max(a, b)}].push_back({f, o});
        h.mass[a] += 0.08 * area(f) / 3;
      }
    for (const auto& [e, fo] : faces) {
      if (fo.size() != 2) continue;
      const int x0 = e.first, x1 = e.second, x2 = fo[0].second, x3 = fo[1].second;
      const int f0 = fo[0].first, f1 = fo[1].first;
      const double c01 = cot(f0, x0, x1, x2), c02 = cot(f1, x0, x1, x3), c03 = cot(f0, x1, x0, x2),
                   c04 = cot(f1, x1, x0, x3);
      h.bends.push_back({{x0, x1, x2, x3},
                         {c03 + c04, c01 + c02, -c01 - c03, -c02 - c04},
                         2e-6 / (area(fo[0].first) + area(fo[1].first))});
    }
    for (int v : s.g.pinned) h.fixed[v] = 1;
    return h;
  }();
  return hg;
}

void BM_ImplicitBending(benchmark::State& st) {
  const Shirt& s = shirt();
  const Hinges& hg = hinges();
  const int nv = static_cast<int>(s.x.rows());
  const double h = 1.0 / (30 * st.range(1));
  sim::ImplicitBending bending(nv, hg.bends, hg.mass, hg.fixed,
                               st.range(2) ? 0.0 : sim::ImplicitBending::kJacobiMaxRatio);
  sim::ImplicitBending factored(nv, hg.bends, hg.mass, hg.fixed, 0.0);
  gdsr::Points3 x = s.x, ref = s.x;
  bending.solve(h, x);  // factors, if it is to
  factored.solve(h, ref);
  const int levels = omp_get_max_active_levels();
  for (auto _ : st) {
    x = s.x;
    if (st.range(0) == 2) {
      bending.solve(h, x);
    } else {  // nested in a region with nesting off: the solve's own region gets one thread
      omp_set_max_active_levels(1);
#pragma omp parallel num_threads(2)
      if (omp_get_thread_num() == 0) bending.solve(h, x);
      omp_set_max_active_levels(levels);
    }
  }
  st.counters["vertices"] = nv;
  st.counters["ratio"] = bending.dominance_ratio(h);
  st.counters["iterations"] = bending.last_iterations();
  st.counters["err_m"] = (x - ref).cwiseAbs().maxCoeff();
}
BENCHMARK(BM_ImplicitBending)
    ->ArgNames({"threads", "substeps", "factored"})
    ->ArgsProduct({{1, 2}, {20, 40}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One self-contact pass (SelfCollision::project) over two 1 m sheets at 10 mm (23k vertices)
// 6 mm apart, uneven by up to 0.5 mm, detected at rest 5 mm thick (20 pairs per vertex); then
// the upper sheet is pressed down by press_um where x < -0.3 m (a fold: a fifth of the cloth) or
// everywhere (all): pairs too close, pushed, and the pairs next to the pushes redone in the
// second phase. Pressed all over, it redoes nearly every pair, and the passes mostly run in
// order. Each time from the same positions. Measured (2026-12-03): 19.1 -> 12.9 ms with nothing
// pressed, 22.5 -> 23.6 ms pressed in the strip, 21.0 -> 24.3 ms pressed all over: the two
// phases gain where pushes are sparse, as on the HR t-shirt (a pass redoes 14-23% of its pairs
// there; `gdsr data make` 4-8% faster per HR frame), and lose where 20 pairs per vertex crowd
// every push. Counters: pairs, pushed (first pass), and `same` = 1
// when one pass on two threads gives the one-thread positions bit for bit.
void BM_SelfContactProjection(benchmark::State& st) {
  static const gdsr_test::CrumpledSheets sheets(8, 1.0, 0.006, 0.0005);
  const auto& m = sheets.m;
  const int nv = static_cast<int>(m.V.rows());
  const double thickness = 0.005;
  const std::vector<double> winv(nv, 1.0);
  gdsr::Points3 pressed = sheets.x;
  const bool all = st.range(2) != 0;
  for (int v = nv / 2; v < nv; ++v)
    if (all || pressed(v, 0) < -0.3) pressed(v, 1) -= 1e-6 * static_cast<double>(st.range(1));
  auto detected = [&] {
    auto sc = std::make_unique<sim::SelfCollision>(m.F, nv);
    sc->detect(sheets.x, gdsr::Points3::Zero(nv, 3), 0.001, thickness);
    return sc;
  };
  const int threads = omp_get_max_threads();
  gdsr::Points3 one = pressed, two = pressed;
  omp_set_num_threads(1);
  const int pushed = detected()->project(one, winv, thickness, thickness, 0.25);
  omp_set_num_threads(2);
  detected()->project(two, winv, thickness, thickness, 0.25);
  const auto sc = detected();
  omp_set_num_threads(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    gdsr::Points3 y = pressed;
    sc->project(y, winv, thickness, thickness, 0.25);
    benchmark::DoNotOptimize(y.data());
  }
  omp_set_num_threads(threads);
  st.counters["pairs"] = sc->num_vertex_triangle() + sc->num_edge_edge();
  st.counters["pushed"] = pushed;
  st.counters["same"] = (one - two).cwiseAbs().maxCoeff() == 0.0;
}
BENCHMARK(BM_SelfContactProjection)
    ->ArgNames({"threads", "press_um", "all"})
    ->Args({1, 0, 0})
    ->Args({2, 0, 0})
    ->Args({1, 1500, 0})
    ->Args({2, 1500, 0})
    ->Args({1, 1500, 1})
    ->Args({2, 1500, 1})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

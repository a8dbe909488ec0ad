// Body queries against the 01_01 body: closest points (1k / 15k garment-like points near
// the surface, and far points; Embree's BodyQuery and the cloth solver's SurfaceGrid, which
// answers only within its search radius), the max_distance knob (time vs fraction of points left
// without an answer), ray casts, per-frame update + commit (rebuild vs refit, and the query
// speed each leaves behind), and load_body_sequence seconds per frame.
#include "gdsr/body/body.hpp"
#include "gdsr/body/body_query.hpp"
#include "gdsr/sim/cloth_collision.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

using namespace gdsr;

namespace {

const std::string kClip = "/usr/share/assimp/models/BVH/01_01.bvh";

const BodySequence& body() {
  static const BodySequence s = [] {
    BodyOptions o;
    o.max_seconds = 12.0;
    return load_body_sequence(kClip, o);
  }();
  return s;
}

// Points within [-1, +8] cm of the surface along the vertex normal (like garment vertices).
Points3 near_points(const TriMesh& m, int n, unsigned seed) {
  const BodyQuery q(m);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> off(-0.01, 0.08);
  Points3 P(n, 3);
  for (int i = 0; i < n; ++i) {
    const int v = static_cast<int>(rng() % m.V.rows());
    P.row(i) = m.V.row(v) + off(rng) * q.vertex_normals().row(v);
  }
  return P;
}

Points3 far_points(const TriMesh& m, int n, unsigned seed) {
  std::mt19937 rng(seed);
  const Eigen::RowVector3d lo = m.V.colwise().minCoeff().array() - 0.5, hi = m.V.colwise().maxCoeff().array() + 0.5;
  std::uniform_real_distribution<double> U(0, 1);
  Points3 P(n, 3);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) P(i, k) = lo[k] + (hi[k] - lo[k]) * U(rng);
  return P;
}

void BM_ClosestNear(benchmark::State& st) {
  const TriMesh m = body().frame_mesh(100);
  const BodyQuery q(m);
  const Points3 P = near_points(m, static_cast<int>(st.range(0)), 1);
  for (auto _ : st) benchmark::DoNotOptimize(q.closest(P));
  st.SetItemsProcessed(st.iterations() * P.rows());
  st.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(st.iterations() * P.rows()), benchmark::Counter::kIsRate);
  st.counters["triangles"] = static_cast<double>(m.F.rows());
}
BENCHMARK(BM_ClosestNear)->Arg(1000)->Arg(15000)->UseRealTime()->Unit(benchmark::kMicrosecond);

// The cloth solver's body grid (gdsr/sim/cloth_collision.hpp) as the solver uses it: built
// over two consecutive frames, queried at their blend within thickness + contact radius
// (0.034 m), one query per point, points in parallel. found: fraction of points with a face
// within the radius (the near points reach 8 cm off the surface).
void BM_SolverGridNear(benchmark::State& st) {
  const TriMesh m0 = body().frame_mesh(100), m1 = body().frame_mesh(101);
  sim::SurfaceGrid grid;
  grid.build(m0.F, m0.V, m1.V, 0.05);
  const Points3 mid = 0.5 * (m0.V + m1.V);
  const Points3 P = near_points(m0, static_cast<int>(st.range(0)), 1);
  const int n = static_cast<int>(P.rows());
  std::vector<int> face(n);
  for (auto _ : st) {
#pragma omp parallel for schedule(dynamic, 256)
    for (int i = 0; i < n; ++i) face[i] = grid.closest(P.row(i).transpose(), mid, 0.034).face;
    benchmark::DoNotOptimize(face.data());
  }
  st.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(st.iterations() * n), benchmark::Counter::kIsRate);
  st.counters["found"] = static_cast<double>(std::count_if(face.begin(), face.end(), [](int f) { return f >= 0; })) / n;
}
BENCHMARK(BM_SolverGridNear)->Arg(1000)->Arg(15000)->UseRealTime()->Unit(benchmark::kMicrosecond);

void BM_ClosestFar(benchmark::State& st) {
  const TriMesh m = body().frame_mesh(100);
  const BodyQuery q(m);
  const Points3 P = far_points(m, static_cast<int>(st.range(0)), 2);
  for (auto _ : st) benchmark::DoNotOptimize(q.closest(P));
  st.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(st.iterations() * P.rows()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ClosestFar)->Arg(1000)->Arg(15000)->UseRealTime()->Unit(benchmark::kMicrosecond);

// max_distance (cm) as a speed knob: error = fraction of near points left without a face.
void BM_ClosestMaxDistance(benchmark::State& st) {
  const TriMesh m = body().frame_mesh(100);
  const BodyQuery q(m);
  const Points3 P = near_points(m, 15000, 3);
  const double r = st.range(0) / 100.0;
  double missed = 0;
  for (auto _ : st) {
    const ClosestPoints c = q.closest(P, true, r);
    missed = (c.face.array() < 0).cast<double>().mean();
  }
  st.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(st.iterations() * P.rows()), benchmark::Counter::kIsRate);
  st.counters["missed_fraction"] = missed;
}
BENCHMARK(BM_ClosestMaxDistance)->Arg(2)->Arg(5)->Arg(10)->UseRealTime()->Unit(benchmark::kMicrosecond);

void BM_Rays(benchmark::State& st) {
  const TriMesh m = body().frame_mesh(100);
  const BodyQuery q(m);
  const Points3 O = far_points(m, static_cast<int>(st.range(0)), 4);
  Points3 D = (near_points(m, static_cast<int>(st.range(0)), 5) - O).rowwise().normalized();
  double hit = 0;
  for (auto _ : st) {
    const RayHits h = q.intersect(O, D);
    hit = (h.face.array() >= 0).cast<double>().mean();
  }
  st.counters["rays_per_s"] =
      benchmark::Counter(static_cast<double>(st.iterations() * O.rows()), benchmark::Counter::kIsRate);
  st.counters["hit_fraction"] = hit;
}
BENCHMARK(BM_Rays)->Arg(15000)->UseRealTime()->Unit(benchmark::kMicrosecond);

// update + commit per frame; arg 0 = rebuild, 1 = refit.
void BM_UpdateCommit(benchmark::State& st) {
  const BodySequence& s = body();
  BodyQuery q(s.frame_mesh(0), st.range(0) ? BodyQuery::Update::Refit : BodyQuery::Update::Rebuild);
  int t = 0;
  for (auto _ : st) {
    q.update(s.frames[t]);
    t = (t + 1) % s.num_frames();
  }
  st.counters["vertices"] = static_cast<double>(s.rest_V.rows());
}
BENCHMARK(BM_UpdateCommit)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMicrosecond);

// Query speed late in the clip after updating every frame from the rest pose (refit
// degrades the BVH built at the rest pose; rebuild does not).
void BM_ClosestAfterUpdates(benchmark::State& st) {
  const BodySequence& s = body();
  BodyQuery q(s.frame_mesh(0), st.range(0) ? BodyQuery::Update::Refit : BodyQuery::Update::Rebuild);
  const int last = s.num_frames() - 1;
  for (int t = 1; t <= last; ++t) q.update(s.frames[t]);
  const Points3 P = near_points(s.frame_mesh(last), 15000, 6);
  for (auto _ : st) benchmark::DoNotOptimize(q.closest(P));
  st.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(st.iterations() * P.rows()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ClosestAfterUpdates)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMicrosecond);

// Whole 01_01 clip at 30 fps: meshing once + skinning every frame.
void BM_LoadSequence(benchmark::State& st) {
  int frames = 0;
  for (auto _ : st) frames = load_body_sequence(kClip).num_frames();
  st.counters["frames"] = frames;
  st.counters["s_per_frame"] = benchmark::Counter(static_cast<double>(st.iterations() * frames),
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LoadSequence)->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

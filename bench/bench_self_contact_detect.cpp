// One self-contact detection (SelfCollision::detect: Embree's broad phase, then the exact narrow
// phase, on two threads) of two crumpled 1 m sheets at 10 mm (23k vertices, uneven by up to
// 0.5 mm, each vertex moving up to 0.5 mm per axis), 5 mm thick with a 1.5 mm slack (the HR
// defaults), `gap_mm` apart: 20 (each sheet's pairs with itself only, 14 per vertex, mostly near
// neighbours within reach: the broad phase's cost, as over most of a garment) or 6 (every vertex
// also near the other sheet, 36 pairs per vertex: the narrow phase's); with the tangle test (rebuild = 1: the broad
// phase's trees built anew, as at the solver's first detection of a frame) or without (rebuild = 0: refitted to the new
// boxes, as at the others). Each time from the same positions. Counters: the vertex-triangle and edge-edge pairs kept.
// Run with nothing else on the machine. Measured (2026-12-03; two runs of each binary, alternated), before -> after the
// vertex boxes were taken once per detection instead of per primitive: 20 mm refitted 86.0, 90.3 -> 77.2, 81.4 ms;
// rebuilt 187, 195 -> 181, 179 ms; 6 mm refitted 171, 159 -> 173, 165 ms; rebuilt 277, 264 -> 261, 271 ms (the narrow
// phase's pairs dominate there: unchanged within the noise).
#include <benchmark/benchmark.h>

#include "gdsr/sim/cloth_self_collision.hpp"
#include "tests/support/crumpled_sheets.hpp"

namespace {

void BM_SelfContactDetect(benchmark::State& st) {
  const gdsr_test::CrumpledSheets sheets(8, 1.0, 1e-3 * static_cast<double>(st.range(0)), 0.0005);
  const int nv = static_cast<int>(sheets.m.V.rows());
  const double slack = 0.0015, thickness = 0.005;
  const gdsr::Points3 motion = 0.25 * sheets.motion;
  const bool rebuild = st.range(1) != 0;
  sim::SelfCollision sc(sheets.m.F, nv);
  sc.detect(sheets.x, motion, slack, thickness);
  for (auto _ : st) sc.detect(sheets.x, motion, slack, thickness, rebuild);
  st.counters["vt_pairs"] = sc.num_vertex_triangle();
  st.counters["ee_pairs"] = sc.num_edge_edge();
}
BENCHMARK(BM_SelfContactDetect)
    ->ArgNames({"gap_mm", "rebuild"})
    ->Args({20, 0})
    ->Args({20, 1})
    ->Args({6, 0})
    ->Args({6, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

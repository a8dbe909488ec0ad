// Validity figures (gdsr/data/validity.hpp): the CGAL self-intersection counter on an
// HR-size sheet (96 x 96 quads, 18,432 faces), clean and wrapped through itself, and the
// intersection-stride knob of measure_validity: time per clip next to the error of the
// clean-frame fraction it measures against every frame (stride 1).
#include "gdsr/data/validity.hpp"
#include "gdsr/geometry/self_intersections.hpp"
#include "tests/support/grid_garment.hpp"

#include <benchmark/benchmark.h>

#include <cmath>

namespace {

// Arg 0: a flat sheet (no pairs); arg 1: the sheet wrapped 2.5 times round a cylinder.
void BM_self_intersections(benchmark::State& s) {
  gdsr_test::GridSpec spec(96, 96, 1.0, 1.0);
  if (s.range(0)) spec.bent(5 * M_PI);
  const gdsr::GarmentMesh g = gdsr_test::grid_garment(spec);
  long pairs = 0;
  for (auto _ : s) pairs = gdsr::self_intersections(g.V, g.F).pairs;
  s.counters["faces"] = static_cast<double>(g.F.rows());
  s.counters["pairs"] = static_cast<double>(pairs);
}
BENCHMARK(BM_self_intersections)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// 60 frames, LR 32 x 32 and HR 96 x 96 quads; HR frames t % 7 in {3, 4} overlap themselves.
gdsr::Dataset clip() {
  gdsr::Dataset d;
  d.lr = gdsr_test::grid_garment(gdsr_test::GridSpec(32, 32, 1.0, 1.0));
  d.hr = gdsr_test::grid_garment(gdsr_test::GridSpec(96, 96, 1.0, 1.0));
  const gdsr::Points3 wrapped = gdsr_test::grid_garment(gdsr_test::GridSpec(96, 96, 1.0, 1.0).bent(2.5 * M_PI)).V;
  for (int t = 0; t < 60; ++t) {
    gdsr::Points3 lr = d.lr.V, hr = d.hr.V;
    for (int i = 0; i < lr.rows(); ++i) lr(i, 2) = 0.05 * std::sin(6 * lr(i, 0) + 0.2 * t);
    for (int i = 0; i < hr.rows(); ++i)
      hr(i, 2) = 0.05 * std::sin(6 * hr(i, 0) + 0.2 * t) + 0.003 * std::sin(40 * hr(i, 1));
    d.lr_frames.push_back(lr);
    d.hr_frames.push_back(t % 7 == 3 || t % 7 == 4 ? wrapped : hr);
  }
  d.corr = gdsr::compute_correspondence(d.lr, d.hr);
  d.raster = gdsr::rasterize_uv(d.hr.UV, d.hr.FUV, 64, 64, 2);
  gdsr::update_manifest_counts(d);
  return d;
}

// Arg: the intersection stride.
void BM_measure_validity(benchmark::State& s) {
  static const gdsr::Dataset d = clip();
  static const double exact = gdsr::measure_validity(d).hr.si_clean_fraction();  // every frame
  gdsr::ValidityOptions opt;
  opt.intersection_stride = static_cast<int>(s.range(0));
  gdsr::ValidityFigures v;
  for (auto _ : s) v = gdsr::measure_validity(d, opt);
  s.counters["frames_checked"] = v.hr.si_frames;
  s.counters["hr_clean_fraction"] = v.hr.si_clean_fraction();
  s.counters["abs_error_vs_stride_1"] = std::abs(v.hr.si_clean_fraction() - exact);
}
BENCHMARK(BM_measure_validity)->Arg(1)->Arg(3)->Arg(5)->Arg(10)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();

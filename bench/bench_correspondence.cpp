// LR <-> HR correspondences: time to build (grid point location in UV, k-d tree), time to
// apply (upsample / downsample per frame) and the UV raster, with the interpolation error
// of an affine field next to the time (must be ~1e-15: any barycentric map reproduces it).
// Meshes: a seamed tube pattern at LR particle distance ~ 3x the HR one, like 30 mm / 10 mm.
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/uv_raster.hpp"

#include <benchmark/benchmark.h>

#include <cmath>

namespace {

// Tube pattern of nx x ny quads over 1.2 m x 0.6 m (last column welded to the first).
gdsr::GarmentMesh tube(int nx, int ny) {
  const double w = 1.2, h = 0.6, R = w / (2 * M_PI);
  gdsr::GarmentMesh g;
  const int cols = nx + 1;
  g.UV.resize(cols * (ny + 1), 2);
  g.V.resize(nx * (ny + 1), 3);
  g.uv_to_vertex.resize(g.UV.rows());
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      g.UV.row(j * cols + i) << w * i / nx, h * j / ny;
      g.uv_to_vertex[j * cols + i] = j * nx + (i % nx);
      if (i < nx) g.V.row(j * nx + i) << R * std::cos(2 * M_PI * i / nx), h * j / ny, R * std::sin(2 * M_PI * i / nx);
    }
  g.FUV.resize(2 * nx * ny, 3);
  int f = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * cols + i;
      g.FUV.row(f++) << a, a + 1, a + cols + 1;
      g.FUV.row(f++) << a, a + cols + 1, a + cols;
    }
  g.F.resize(g.FUV.rows(), 3);
  for (int t = 0; t < g.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) g.F(t, k) = g.uv_to_vertex[g.FUV(t, k)];
  return g;
}

// An affine function of the UV position of each welded vertex (first UV copy).
gdsr::Points3 affine(const gdsr::GarmentMesh& g) {
  gdsr::Points3 P(g.V.rows(), 3);
  for (int u = static_cast<int>(g.UV.rows()) - 1; u >= 0; --u) {
    const double a = g.UV(u, 0), b = g.UV(u, 1);
    P.row(g.uv_to_vertex[u]) << 2 * a - b, 0.5 * a + 3 * b, 1 - a;
  }
  return P;
}

// Arg: HR quads along the width (LR has a third of it).
void BM_compute_correspondence(benchmark::State& s) {
  const int n = static_cast<int>(s.range(0));
  const gdsr::GarmentMesh lr = tube(n / 3, n / 6), hr = tube(n, n / 2);
  gdsr::Correspondence c;
  for (auto _ : s) c = gdsr::compute_correspondence(lr, hr);
  // A welded seam vertex carries the field of its u = 0 copy, so the last LR column (whose
  // triangles touch the seam from the u = 1.2 side) is not affine: compare elsewhere.
  const gdsr::Points3 err = gdsr::upsample(c, affine(lr)) - affine(hr);
  const std::vector<int> first = gdsr::first_uv_copy(hr.uv_to_vertex, static_cast<int>(hr.V.rows()));
  const double last_column = 1.2 * (1.0 - 1.0 / (n / 3));
  double e = 0;
  for (int i = 0; i < err.rows(); ++i)
    if (hr.UV(first[i], 0) < last_column - 1e-9) e = std::max(e, err.row(i).cwiseAbs().maxCoeff());
  s.counters["lr_verts"] = static_cast<double>(lr.V.rows());
  s.counters["hr_verts"] = static_cast<double>(hr.V.rows());
  s.counters["affine_err"] = e;
}
BENCHMARK(BM_compute_correspondence)->Arg(96)->Arg(192)->Arg(300)->Unit(benchmark::kMillisecond);

void BM_upsample(benchmark::State& s) {
  const int n = static_cast<int>(s.range(0));
  const gdsr::GarmentMesh lr = tube(n / 3, n / 6), hr = tube(n, n / 2);
  const gdsr::Correspondence c = gdsr::compute_correspondence(lr, hr);
  const gdsr::Points3 x = lr.V;
  for (auto _ : s) benchmark::DoNotOptimize(gdsr::upsample(c, x).data());
  s.counters["hr_verts"] = static_cast<double>(hr.V.rows());
  s.counters["roundtrip_err"] = (gdsr::downsample(c, gdsr::upsample(c, x)) - x).cwiseAbs().maxCoeff();
}
BENCHMARK(BM_upsample)->Arg(96)->Arg(300)->Unit(benchmark::kMicrosecond);

void BM_downsample(benchmark::State& s) {
  const int n = static_cast<int>(s.range(0));
  const gdsr::GarmentMesh lr = tube(n / 3, n / 6), hr = tube(n, n / 2);
  const gdsr::Correspondence c = gdsr::compute_correspondence(lr, hr);
  for (auto _ : s) benchmark::DoNotOptimize(gdsr::downsample(c, hr.V).data());
  s.counters["lr_verts"] = static_cast<double>(lr.V.rows());
}
BENCHMARK(BM_downsample)->Arg(96)->Arg(300)->Unit(benchmark::kMicrosecond);

// Arg: raster size in pixels (HR mesh fixed at ~10k vertices).
void BM_rasterize_uv(benchmark::State& s) {
  const gdsr::GarmentMesh hr = tube(192, 96);
  const int px = static_cast<int>(s.range(0));
  gdsr::UVRaster r;
  for (auto _ : s) r = gdsr::rasterize_uv(hr.UV, hr.FUV, px, px);
  double worst = 0;
  int covered = 0;
  for (int j = 0; j < r.height; ++j)
    for (int i = 0; i < r.width; ++i) {
      const size_t p = static_cast<size_t>(j) * r.width + i;
      if (r.tri[p] < 0) continue;
      ++covered;
      Eigen::Vector2d uv = Eigen::Vector2d::Zero();
      for (int k = 0; k < 3; ++k) uv += r.bary[p * 3 + k] * hr.UV.row(hr.FUV(r.tri[p], k)).transpose();
      worst = std::max(worst, (uv - r.pixel_center_uv(i, j)).norm() * r.scale);  // in pixels
    }
  s.counters["covered_px"] = covered;
  s.counters["centre_err_px"] = worst;
}
BENCHMARK(BM_rasterize_uv)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

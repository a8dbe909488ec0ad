// Throughput of the reference MLP block (forward + backward, float32) next to plain Eigen
// GEMMs of the same shapes, and of the complex grouped linear op (the hyper-network field).
// The program keeps large blocks in the heap and waits passively (autograd/runtime.hpp), so
// gradient buffers are not page-faulted in again every iteration.
// Counters: GFLOP/s over the GEMM flops only (elementwise work is not counted), per second
// of process CPU time (all threads): robust on a shared, loaded machine. Run with
// OMP_NUM_THREADS=1 for single-core numbers, or compare "Time" for wall-clock.
//
//   MLP block: Linear 384->128, LeakyReLU(0.02), Linear 128->128, channel_norm, LeakyReLU.
//   Forward GEMM flops 2 R (384*128 + 128*128); backward twice that (dX and dW per layer).
#include "autograd/autograd.hpp"
#include "autograd/runtime.hpp"

#include <benchmark/benchmark.h>

#include <random>

namespace {

constexpr int64_t kIn = 384, kLat = 128;

template <class T> ag::Tensor<T> rand_tensor(const ag::Shape& s, unsigned seed, double scale, bool grad) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd(0.0, scale);
  std::vector<T> v(static_cast<size_t>(ag::numel_of(s)));
  for (auto& x : v) {
    if constexpr (ag::is_complex_v<T>)
      x = T(nd(rng), nd(rng));
    else
      x = T(nd(rng));
  }
  return ag::Tensor<T>::from(s, std::move(v), grad);
}

double mlp_flops(int64_t rows) { return 3.0 * 2.0 * rows * (kIn * kLat + kLat * kLat); }

void BM_MlpBlock(benchmark::State& state) {
  const int64_t R = state.range(0);
  auto x = rand_tensor<float>({R, kIn}, 1, 1.0, true);
  auto w1 = rand_tensor<float>({kLat, kIn}, 2, 0.05, true), b1 = rand_tensor<float>({1, kLat}, 3, 0.1, true);
  auto w2 = rand_tensor<float>({kLat, kLat}, 4, 0.09, true), b2 = rand_tensor<float>({1, kLat}, 5, 0.1, true);
  for (auto _ : state) {
    for (auto* t : {&x, &w1, &b1, &w2, &b2}) t->zero_grad();
    auto h = ag::leaky_relu(ag::linear(x, w1, b1), 0.02f);
    auto y = ag::leaky_relu(ag::channel_norm(ag::linear(h, w2, b2)), 0.02f);
    auto loss = ag::sum(y);
    loss.backward();
    benchmark::DoNotOptimize(w1.grad().data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(mlp_flops(R) * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

// The same six GEMMs with Eigen directly (row-major float, as our tensors are stored).
void BM_EigenGemm(benchmark::State& state) {
  using M = ag::RowMat<float>;
  const int64_t R = state.range(0);
  const M x = M::Random(R, kIn), w1 = M::Random(kLat, kIn), w2 = M::Random(kLat, kLat);
  const M g = M::Random(R, kLat);
  M h(R, kLat), y(R, kLat), dh(R, kLat), dx(R, kIn), dw1(kLat, kIn), dw2(kLat, kLat);
  for (auto _ : state) {
    h.noalias() = x * w1.transpose();
    y.noalias() = h * w2.transpose();
    dw2.noalias() = g.transpose() * h;
    dh.noalias() = g * w2;
    dw1.noalias() = dh.transpose() * x;
    dx.noalias() = dh * w1;
    benchmark::DoNotOptimize(dx.data());
    benchmark::DoNotOptimize(dw1.data());
    benchmark::DoNotOptimize(y.data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(mlp_flops(R) * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

// grouped_linear, complex64: G groups of n/G rows, in = out = 64, forward + backward.
constexpr int64_t kGroups = 2300, kRows = 15000, kF = 64;
double grouped_flops() { return 3.0 * 8.0 * kRows * kF * kF; }  // complex MAC = 8 flops
// Least memory traffic of forward + backward: each group's 64 x 64 complex weights are read
// twice (y, dX) and their gradient written once, plus x, y, dy and dX rows once each. With
// ~6.5 rows per group that is ~6.5 flops per byte of weights, where one dense GEMM of the
// same flops keeps its weights in cache. Its GB/s next to BM_StreamWeightBlocks' tells how
// close the op is to the memory bound (measured: 6 of 39 GB/s, so the kernels, not memory,
// are what keep it at a third of the dense rate).
double grouped_min_bytes() { return 8.0 * (3.0 * kGroups * kF * kF + 4.0 * kRows * kF); }

void BM_GroupedLinearComplex(benchmark::State& state) {
  using C = std::complex<float>;
  const bool sorted = state.range(0) != 0;
  auto x = rand_tensor<C>({kRows, kF}, 6, 1.0, true);
  auto w = rand_tensor<C>({kGroups, kF * kF}, 7, 0.1, true), b = rand_tensor<C>({kGroups, kF}, 8, 0.1, true);
  ag::Index group(kRows);
  std::mt19937 rng(9);
  for (auto& g : group) g = std::uniform_int_distribution<int64_t>(0, kGroups - 1)(rng);
  if (sorted) std::sort(group.begin(), group.end());
  for (auto _ : state) {
    for (auto* t : {&x, &w, &b}) t->zero_grad();
    auto y = ag::grouped_linear(x, w, b, group, kF);
    ag::sum(ag::real(y)).backward();
    benchmark::DoNotOptimize(w.grad().data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(grouped_flops() * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["GB/s"] =
      benchmark::Counter(grouped_min_bytes() * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

// The same on the layout GDSR's field uses: weights and bias read in place from two real
// planes (the hyper-network's output, grouped_linear_planes), rows sorted by group.
// fresh_grads:1 drops the gradients every iteration, as the field's planes are fresh in every
// training step: the op claims its columns and writes dW without a zero fill or a read of the
// old values (Node::claim_grad_columns), as the dense GEMM yardstick writes its dW.
// fresh_grads:0 adds into the existing 77 MB of gradients (read, add, write back).
void BM_GroupedLinearPlanes(benchmark::State& state) {
  const bool fresh = state.range(0) != 0;
  using C = std::complex<float>;
  const int64_t P = kF * kF + kF;  // weights, then bias
  auto x = rand_tensor<C>({kRows, kF}, 6, 1.0, true);
  auto re = rand_tensor<float>({kGroups, P}, 7, 0.1, true), im = rand_tensor<float>({kGroups, P}, 8, 0.1, true);
  ag::Index group(kRows);
  std::mt19937 rng(9);
  for (auto& g : group) g = std::uniform_int_distribution<int64_t>(0, kGroups - 1)(rng);
  std::sort(group.begin(), group.end());
  for (auto _ : state) {
    if (fresh)
      for (auto* t : {&re, &im}) t->zero_grad();
    auto y = ag::grouped_linear_planes(x, re, im, 0, kF * kF, group, kF);
    ag::sum(ag::real(y)).backward();
    benchmark::DoNotOptimize(re.grad().data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(grouped_flops() * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["GB/s"] =
      benchmark::Counter(grouped_min_bytes() * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

// The memory yardstick of the grouped op: one pass that reads a weight-sized complex block
// and writes another of the same size, twice over (the op's least traffic is three weight
// blocks: W read in forward and again for dX, dW written). GB/s counted like the op's.
void BM_StreamWeightBlocks(benchmark::State& state) {
  using C = std::complex<float>;
  std::vector<C> a(static_cast<size_t>(kGroups * kF * kF), C(1, 2)), b(a.size());
  for (auto _ : state) {
    for (int rep = 0; rep < 2; ++rep) {
      const C* pa = a.data();
      C* pb = b.data();
      const int64_t n = static_cast<int64_t>(a.size());
#pragma omp parallel for schedule(static)
      for (int64_t i = 0; i < n; ++i) pb[i] = pa[i] * 0.5f;
    }
    benchmark::DoNotOptimize(b.data());
  }
  state.counters["GB/s"] =
      benchmark::Counter(4.0 * sizeof(C) * kGroups * kF * kF * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

// One dense complex GEMM of the same total size (upper bound for the grouped op).
void BM_EigenGemmComplexSameFlops(benchmark::State& state) {
  using M = ag::RowMat<std::complex<float>>;
  const M x = M::Random(kRows, kF), w = M::Random(kF, kF), g = M::Random(kRows, kF);
  M y(kRows, kF), dx(kRows, kF), dw(kF, kF);
  for (auto _ : state) {
    y.noalias() = x * w.transpose();
    dx.noalias() = g * w.conjugate();
    dw.noalias() = g.transpose() * x.conjugate();
    benchmark::DoNotOptimize(y.data());
    benchmark::DoNotOptimize(dx.data());
    benchmark::DoNotOptimize(dw.data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(grouped_flops() * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

BENCHMARK(BM_MlpBlock)->Arg(2000)->Arg(10000)->Arg(30000)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK(BM_EigenGemm)->Arg(2000)->Arg(10000)->Arg(30000)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK(BM_GroupedLinearComplex)
    ->ArgName("sorted")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();
BENCHMARK(BM_GroupedLinearPlanes)
    ->ArgName("fresh_grads")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();
BENCHMARK(BM_EigenGemmComplexSameFlops)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK(BM_StreamWeightBlocks)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

int main(int argc, char** argv) {
  ag::configure_runtime(argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

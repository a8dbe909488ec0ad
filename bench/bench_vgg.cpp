// VGG19 feature extractor (shared blocks 1-3, up to relu3_1): forward and forward+backward
// time per image at the GDSR patch size (80 x 80) and at ImageNet size (224 x 224), float32,
// and the conv op alone. Counter "GFLOPs" = conv multiply-adds x 2 per second.
#include "autograd/autograd.hpp"
#include "nn/feature_loss.hpp"
#include "nn/rng.hpp"
#include "nn/vgg.hpp"

#include <benchmark/benchmark.h>

namespace {
const std::string kWeights = std::string(GDSR_SHARED_DIR) + "/weights/vgg19-imagenet-conv1-conv3";

ag::Tensorf image(int64_t n, int64_t s, uint64_t seed) {
  nn::Rng rng(seed);
  ag::Tensorf t = ag::Tensorf::zeros({n, 3, s, s});
  for (auto& v : t.values()) v = static_cast<float>(rng.uniform(0, 1));
  return t;
}

// Multiply-adds of conv1_1 .. conv3_1 at an s x s input.
double conv_flops(int64_t s) {
  const double p1 = double(s * s), p2 = p1 / 4, p3 = p1 / 16;
  return 2.0 * (p1 * 64 * 27 + p1 * 64 * 576 + p2 * 128 * 576 + p2 * 128 * 1152 + p3 * 256 * 1152);
}

const nn::VGG19Features<float>& vgg() {
  static const nn::VGG19Features<float> v(kWeights);
  return v;
}

void BM_VggForward(benchmark::State& st) {
  const int64_t s = st.range(0);
  const ag::Tensorf img = image(1, s, 1);
  ag::NoGradGuard ng;
  for (auto _ : st) benchmark::DoNotOptimize(vgg().features(img));
  st.counters["GFLOPs"] = benchmark::Counter(conv_flops(s) * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_VggForward)->Arg(80)->Arg(224)->Unit(benchmark::kMillisecond);

// The training use: cosine VGG loss of a predicted patch against a target patch, gradient
// to the predicted image (target features without a graph).
void BM_VggLossBackward(benchmark::State& st) {
  const int64_t s = st.range(0);
  const ag::Tensorf target = image(1, s, 2);
  for (auto _ : st) {
    ag::Tensorf pred = image(1, s, 3);
    pred.set_requires_grad(true);
    ag::Tensorf l = nn::vgg_loss(vgg(), pred, target);
    l.backward();
    benchmark::DoNotOptimize(pred.grad().data());
  }
}
BENCHMARK(BM_VggLossBackward)->Arg(80)->Arg(224)->Unit(benchmark::kMillisecond);

void BM_Conv64(benchmark::State& st) {
  const int64_t s = st.range(0);
  nn::Rng rng(4);
  ag::Tensorf x = ag::Tensorf::zeros({1, 64, s, s}), w = ag::Tensorf::zeros({64, 64, 3, 3}),
              b = ag::Tensorf::zeros({64});
  for (auto& v : x.values()) v = static_cast<float>(rng.normal(0, 1));
  for (auto& v : w.values()) v = static_cast<float>(rng.normal(0, 0.05));
  ag::NoGradGuard ng;
  for (auto _ : st) benchmark::DoNotOptimize(ag::conv2d_3x3(x, w, b));
  st.counters["GFLOPs"] =
      benchmark::Counter(2.0 * double(s * s) * 64 * 576 * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_Conv64)->Arg(80)->Arg(224)->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();

// A small model overfits one frame pair with the project's losses (gdsr/losses.hpp):
// coarse loss on C_hat and fine loss on two fixed UV patches, optimised with Adam.
// The smoothness terms are switched off here: they are absolute regularisers (not measured
// against the ground truth) whose value at the ground truth itself is not zero, so they
// would put a floor under the total; every other term compares with the ground truth
// and can go to zero. VGG is off (no weights needed in the unit tests).
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "train/losses.hpp"
#include "gdsr/model/model_config.hpp"
#include "train/patches.hpp"
#include "gdsr/geometry/uv_raster.hpp"
#include "tests/support/model_test_util.hpp"

#include <cmath>
#include <random>
#include <sstream>
#include <string>

using namespace gdsr;

namespace {
// Plain Adam over the model's parameters (independent of nn's optimiser).
template <class T> struct Adam {
  std::vector<ag::Tensor<T>> params;
  std::vector<std::vector<T>> m, v;
  double lr, b1 = 0.9, b2 = 0.999, eps = 1e-8;
  int t = 0;
  Adam(std::vector<ag::Tensor<T>> p, double lr_) : params(std::move(p)), lr(lr_) {
    for (auto& x : params) m.emplace_back(x.numel(), T(0)), v.emplace_back(x.numel(), T(0));
  }
  void step(double lr_now) {
    lr = lr_now;
    ++t;
    const double c1 = 1 - std::pow(b1, t), c2 = 1 - std::pow(b2, t);
    for (size_t k = 0; k < params.size(); ++k) {
      if (!params[k].has_grad()) continue;
      const auto& g = params[k].grad();
      auto& w = params[k].values();
      for (size_t i = 0; i < w.size(); ++i) {
        m[k][i] = T(b1 * m[k][i] + (1 - b1) * g[i]);
        v[k][i] = T(b2 * v[k][i] + (1 - b2) * g[i] * g[i]);
        w[i] -= T(lr * (m[k][i] / c1) / (std::sqrt(v[k][i] / c2) + eps));
      }
      params[k].zero_grad();
    }
  }
};

struct Overfit {
  double first = 0, last = 0, first_c = 0, last_c = 0, first_f = 0, last_f = 0;
  std::string report;
};

// Fits one frame pair with a model initialised from `seed`.
template <class T> Overfit overfit(uint64_t seed) {
  const double size = 0.2;
  const GarmentMesh lr = gdsr_test::grid_garment(gdsr_test::GridSpec::square(5, size));
  GarmentMesh hr = gdsr_test::grid_garment(gdsr_test::GridSpec::square(17, size));
  const Correspondence corr = compute_correspondence(lr, hr);

  // Ground truth: a bulge with small wrinkles along x; C* is its downsampling.
  Points3 G_star = hr.V;
  for (int i = 0; i < G_star.rows(); ++i) {
    const double x = G_star(i, 0) / size, z = G_star(i, 2) / size;
    G_star(i, 1) += 0.03 * std::sin(M_PI * x) * std::sin(M_PI * z) + 0.004 * std::sin(6 * M_PI * x);
  }
  const Points3 C_star = downsample(corr, G_star);
  FrameInput in;
  in.C_t = C_star;
  for (int i = 0; i < in.C_t.rows(); ++i) in.C_t(i, 1) -= 0.01 * std::sin(M_PI * in.C_t(i, 0) / size);
  in.C_tm1 = in.C_t;
  in.C_tm2 = in.C_t;
  in.Chat_tm1 = C_star;
  in.Chat_tm2 = C_star;

  ModelConfig cfg = load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/small.json");
  cfg.mp_steps = 2;
  cfg.seed = seed;
  GDSR<T> model(cfg);
  const GarmentGraph g = build_graph(lr);

  PatchConfig pc;
  pc.size = 40;
  pc.count = 2;
  const PatchSampler sampler(rasterize_uv(hr.UV, hr.FUV, 128, 128, 4), hr, corr.hr_from_lr.tri, pc);
  std::mt19937_64 prng(3);
  const PatchBatch batch = sampler.sample(prng);
  const HrRequest req = hr_request_subset(corr, batch.vertices);
  const MeshTopology lr_topo = make_topology(lr);

  LossConfig lc;
  lc.c_smooth.on = false;
  lc.f_smooth.on = false;
  lc.f_vgg.on = false;
  lc.schedule = false;

  const double lr0 = 1e-3;
  const int steps = 600, warmup = 100;
  Adam<T> opt(model.parameters(), lr0);
  Overfit r;
  for (int s = 0; s < steps; ++s) {
    const auto out = model.forward(g, in, &req);
    const auto c = coarse_loss(lc, lr_topo, out.C_hat, C_star);
    const auto f = fine_loss(lc, batch, out.G, G_star);
    const ag::Tensor<T> total = total_loss(Lambdas{1, 1}, c.total, f.total);
    const double v = total.item();
    REQUIRE(std::isfinite(v));
    if (s == 0) r.first = v, r.first_c = c.total.item(), r.first_f = f.total.item();
    r.last = v, r.last_c = c.total.item(), r.last_f = f.total.item();
    total.backward();
    // A linear warm-up over the first 100 steps, then a linear decay to 10%. Without the
    // warm-up (the full rate from the first step) about half the initialisations stuck on a
    // plateau at 2e-3 (2 of 16 at 1e-3): fine loss 1.76e-3, A's field never learns the wrinkles,
    // a 3-8x drop only. Which ones
    // changed with rounding: float32 and float64 runs of the same seed ended on different
    // sides, so float64 alone did not make the test robust. With the warm-up 24 of 24 seeds fell
    // 166-442x (fine) and relative changes of 1e-7 to 3e-6 to the initial parameters moved
    // seed 1's result by less than 2x. Without the decay Adam keeps oscillating near the
    // minimum and the last loss depends on float32 rounding.
    opt.step(lr0 * (1.0 - 0.9 * s / steps) * (s < warmup ? double(s + 1) / warmup : 1.0));
  }
  std::ostringstream m;
  m << "seed " << seed << ": loss " << r.first << " -> " << r.last << " (coarse " << r.first_c << " -> " << r.last_c
    << ", fine " << r.first_f << " -> " << r.last_f << ") in " << steps << " Adam steps; " << batch.vertices.size()
    << " HR samples on " << batch.lr_triangles.size() << " LR triangles";
  r.report = m.str();
  return r;
}

}  // namespace

TEST_CASE("model overfit: a small model fits one frame pair (coarse + fine loss drop 10x), 2 of 3 seeds at least") {
  // Three initialisations (float32, as training runs), of which at least two must fit: one
  // unlucky start (a rounding-level change can move a run into another basin) does not fail
  // the test, a model or loss that stops fitting does. Measured: every seed of 1..24 falls
  // 200x or more in total, so two failures out of three would be a real regression.
  int fitted = 0;
  for (uint64_t seed : {1, 2, 3}) {
    const Overfit r = overfit<float>(seed);
    const bool ok = r.last < r.first / 10 && r.last_c < r.first_c / 10 && r.last_f < r.first_f / 10;
    const std::string note = ok ? "" : "  <- did not fall 10x";
    MESSAGE(r.report << note);
    fitted += ok ? 1 : 0;
  }
  CHECK(fitted >= 2);
}

// An MLP (MLPStack + Linear, float32, AdamW) learns a small regression.
#include "train/demo_mlp.hpp"

#include <doctest/doctest.h>

#include <cmath>

TEST_CASE("MLP regression in float32: training loss drops by more than 100x, test loss follows") {
  nn::DemoMlpOptions opt;  // sin(pi x) cos(pi y) on [-1, 1]^2, 256 points, widths {2, 64, 64}
  opt.steps = 600;
  int64_t reports = 0;
  const nn::DemoMlpResult r = nn::train_demo_mlp(opt, [&](int64_t, double l) {
    ++reports;
    CHECK(std::isfinite(l));
  });
  REQUIRE(static_cast<int64_t>(r.loss.size()) == opt.steps);
  const int64_t every = opt.report_every;  // steps 0, every, 2 every, ... and the last one
  CHECK(reports == (opt.steps + every - 1) / every + ((opt.steps - 1) % every ? 1 : 0));
  const double drop = r.loss.front() / r.final_loss;
  MESSAGE("initial loss " << r.loss.front() << ", final " << r.final_loss << " (drop " << drop << "x), test "
                          << r.test_loss << ", " << r.seconds << " s");
  CHECK(drop > 100.0);
  CHECK(r.test_loss < 10.0 * r.final_loss + 1e-3);
}

TEST_CASE("train_demo_mlp: deterministic per seed / bad options refused") {
  nn::DemoMlpOptions opt;
  opt.steps = 20;
  const auto a = nn::train_demo_mlp(opt), b = nn::train_demo_mlp(opt);
  CHECK(a.loss == b.loss);
  opt.seed = 2;
  CHECK(nn::train_demo_mlp(opt).loss != a.loss);
  opt.widths = {3, 8};
  CHECK_THROWS(nn::train_demo_mlp(opt));
}

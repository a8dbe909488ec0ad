#include "train/demo_mlp.hpp"

#include "gdsr/error.hpp"

#include "autograd/ops_elementwise.hpp"
#include "autograd/ops_loss.hpp"
#include "nn/adamw.hpp"
#include "nn/linear.hpp"
#include "nn/mlp.hpp"

#include <chrono>
#include <cmath>

namespace nn {

namespace {
struct Regressor : Module<float> {
  std::shared_ptr<MLPStack<float>> body;
  std::shared_ptr<Linear<float>> head;
  Regressor(const std::vector<int64_t>& widths, Rng& rng) {
    body = register_module("body", std::make_shared<MLPStack<float>>(widths, false, false, rng));
    head = register_module("head", std::make_shared<Linear<float>>(widths.back(), 1, true, rng));
  }
  ag::Tensorf forward(const ag::Tensorf& x) const { return head->forward(body->forward(x)); }
};

void make_data(int64_t n, Rng& rng, ag::Tensorf& x, ag::Tensorf& y) {
  x = ag::Tensorf::zeros({n, 2});
  y = ag::Tensorf::zeros({n, 1});
  const double pi = 3.14159265358979323846;
  for (int64_t i = 0; i < n; ++i) {
    const double a = rng.uniform(-1, 1), b = rng.uniform(-1, 1);
    x.data()[2 * i] = static_cast<float>(a);
    x.data()[2 * i + 1] = static_cast<float>(b);
    y.data()[i] = static_cast<float>(std::sin(pi * a) * std::cos(pi * b));
  }
}
}  // namespace

DemoMlpResult train_demo_mlp(const DemoMlpOptions& opt, const std::function<void(int64_t, double)>& progress) {
  if (opt.widths.size() < 2 || opt.widths.front() != 2)
    gdsr::fail("train_demo_mlp", "widths must start with 2 (the input) and have at least two entries");
  if (opt.samples <= 0 || opt.steps <= 0) gdsr::fail("train_demo_mlp", "samples and steps must be positive");
  Rng rng(opt.seed);
  Regressor model(opt.widths, rng);
  ag::Tensorf x, y, xt, yt;
  make_data(opt.samples, rng, x, y);
  make_data(opt.samples, rng, xt, yt);
  AdamWOptions ao;
  ao.lr = opt.lr;
  ao.weight_decay = opt.weight_decay;
  ao.amsgrad = opt.amsgrad;
  AdamW<float> adam(model.named_parameters(), ao);

  DemoMlpResult res;
  const auto t0 = std::chrono::steady_clock::now();
  for (int64_t s = 0; s < opt.steps; ++s) {
    adam.zero_grad();
    ag::Tensorf loss = ag::mse_loss(model.forward(x), y);
    const double l = loss.item();
    if (!std::isfinite(l))
      gdsr::fail("train_demo_mlp", "loss became " + std::to_string(l) + " at step " + std::to_string(s));
    res.loss.push_back(l);
    if (progress && (s % std::max<int64_t>(1, opt.report_every) == 0 || s + 1 == opt.steps)) progress(s, l);
    loss.backward();
    adam.step();
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ag::NoGradGuard ng;
  res.final_loss = ag::mse_loss(model.forward(x), y).item();
  res.test_loss = ag::mse_loss(model.forward(xt), yt).item();
  return res;
}

}  // namespace nn

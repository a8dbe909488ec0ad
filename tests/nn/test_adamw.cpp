// AdamW against a hand-written reference of torch.optim.AdamW's update, and the schedules.
#include "autograd/autograd.hpp"
#include "nn/adamw.hpp"
#include "nn/lr_schedule.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace {
// Loss at step t: s_t * sum_i c_i p_i^2 (gradient 2 s_t c_i p_i); s_t shrinks so that v
// falls below its running maximum and amsgrad differs from plain Adam.
const double kC[3] = {1.0, -2.0, 0.5};
double scale_at(int t) { return std::pow(0.3, t); }

// Reference, written out with scalars, following the PyTorch documentation's algorithm.
std::vector<std::vector<double>> reference(std::vector<double> p, int steps, double lr, double b1, double b2,
                                           double eps, double wd, bool amsgrad) {
  std::vector<double> m(3, 0.0), v(3, 0.0), vhat(3, 0.0);
  std::vector<std::vector<double>> hist;
  for (int t = 1; t <= steps; ++t) {
    for (int i = 0; i < 3; ++i) {
      const double g = 2.0 * scale_at(t - 1) * kC[i] * p[i];
      p[i] = p[i] - lr * wd * p[i];
      m[i] = b1 * m[i] + (1 - b1) * g;
      v[i] = b2 * v[i] + (1 - b2) * g * g;
      const double mhat = m[i] / (1 - std::pow(b1, t));
      double vh;
      if (amsgrad) {
        vhat[i] = std::max(vhat[i], v[i]);
        vh = vhat[i] / (1 - std::pow(b2, t));
      } else {
        vh = v[i] / (1 - std::pow(b2, t));
      }
      p[i] = p[i] - lr * mhat / (std::sqrt(vh) + eps);
    }
    hist.push_back(p);
  }
  return hist;
}

template <class R> std::vector<std::vector<double>> run(bool amsgrad, int steps, double lr, double wd) {
  ag::Tensor<R> p = ag::Tensor<R>::from({1, 3}, {R(0.8), R(-1.5), R(2.0)}, true);
  const ag::Tensor<R> c = ag::Tensor<R>::from({1, 3}, {R(kC[0]), R(kC[1]), R(kC[2])});
  nn::AdamWOptions o;
  o.lr = lr;
  o.weight_decay = wd;
  o.amsgrad = amsgrad;
  nn::AdamW<R> opt({{"p", p}}, o);
  std::vector<std::vector<double>> hist;
  for (int t = 0; t < steps; ++t) {
    opt.zero_grad();
    ag::sum(ag::mul_scalar(ag::mul(c, ag::square(p)), R(scale_at(t)))).backward();
    opt.step();
    hist.push_back({double(p.values()[0]), double(p.values()[1]), double(p.values()[2])});
  }
  CHECK(opt.steps_taken() == steps);
  return hist;
}

double max_err(const std::vector<std::vector<double>>& a, const std::vector<std::vector<double>>& b) {
  double m = 0;
  for (size_t t = 0; t < a.size(); ++t)
    for (int i = 0; i < 3; ++i) m = std::max(m, std::abs(a[t][i] - b[t][i]));
  return m;
}
}  // namespace

TEST_CASE("AdamW: reproduces the hand-computed update sequence (Adam and AMSGrad, float64 and float32)") {
  const int steps = 8;
  for (bool ams : {false, true}) {
    INFO("amsgrad " << ams);
    const auto ref = reference({0.8, -1.5, 2.0}, steps, 0.05, 0.9, 0.999, 1e-8, 0.1, ams);
    const auto got = run<double>(ams, steps, 0.05, 0.1);
    CHECK(max_err(ref, got) < 1e-13);
    const auto gotf = run<float>(ams, steps, 0.05, 0.1);
    CHECK(max_err(ref, gotf) < 2e-6);
  }
  // The two variants really differ on this sequence (so the amsgrad branch is exercised).
  const auto a = reference({0.8, -1.5, 2.0}, steps, 0.05, 0.9, 0.999, 1e-8, 0.1, false);
  const auto b = reference({0.8, -1.5, 2.0}, steps, 0.05, 0.9, 0.999, 1e-8, 0.1, true);
  CHECK(max_err(a, b) > 1e-5);  // 1.2e-4 here, far above the 1e-13 agreement checked above
}

TEST_CASE("AdamW: first step moves by lr * sign(g) after decoupled decay") {
  ag::Tensord p = ag::Tensord::from({1, 2}, {1.0, -3.0}, true);
  nn::AdamWOptions o;
  o.lr = 0.01;
  o.weight_decay = 0.5;
  nn::AdamW<double> opt({{"p", p}}, o);
  ag::sum(ag::mul(p, ag::Tensord::from({1, 2}, {4.0, 1e-3}))).backward();  // g = (4, 1e-3)
  opt.step();
  CHECK(p.values()[0] == doctest::Approx(1.0 * (1 - 0.005) - 0.01 * 4.0 / (4.0 + 1e-8)).epsilon(1e-14));
  CHECK(p.values()[1] == doctest::Approx(-3.0 * (1 - 0.005) - 0.01 * 1e-3 / (1e-3 + 1e-8)).epsilon(1e-14));
}

TEST_CASE("AdamW: parameters without a gradient are skipped / complex parameters update as real pairs") {
  ag::Tensord a = ag::Tensord::from({1, 1}, {1.0}, true), b = ag::Tensord::from({1, 1}, {2.0}, true);
  ag::Tensorcd z = ag::Tensorcd::from({1, 1}, {std::complex<double>(0.5, -0.25)}, true);
  ag::Tensord re = ag::Tensord::from({1, 2}, {0.5, -0.25}, true);
  nn::AdamW<double> opt;
  opt.add("a", a);
  opt.add("b", b);
  opt.add("z", z);
  nn::AdamW<double> ref;
  ref.add("re", re);
  CHECK_THROWS_AS(opt.add("a", b), ag::Error);
  for (int t = 0; t < 3; ++t) {
    opt.zero_grad();
    ref.zero_grad();
    // L = 3 a + |z|^2 -> grad z = 2 z (PyTorch convention), the same as for (re, im) as reals.
    ag::sum(ag::add(ag::mul_scalar(a, 3.0), ag::sum(ag::square(ag::modulus(z))))).backward();
    ag::sum(ag::square(re)).backward();
    opt.step();
    ref.step();
  }
  CHECK(b.values()[0] == 2.0);
  CHECK(opt.slots()[1].step == 0);
  CHECK(opt.slots()[0].step == 3);
  CHECK(z.values()[0].real() == doctest::Approx(re.values()[0]).epsilon(1e-14));
  CHECK(z.values()[0].imag() == doctest::Approx(re.values()[1]).epsilon(1e-14));
}

TEST_CASE("AdamW: options outside the domain of the update are refused naming the option") {
  // eps = 0 would turn an entry whose gradient and moments are 0 into 0 / 0 = NaN; beta = 1
  // makes the bias correction 1 - beta^t zero.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<std::pair<std::function<void(nn::AdamWOptions&)>, std::string>> bad = {
      {[](auto& o) { o.eps = 0; }, "eps"},          {[](auto& o) { o.eps = -1e-8; }, "eps"},
      {[nan](auto& o) { o.eps = nan; }, "eps"},     {[](auto& o) { o.beta1 = 1; }, "beta1"},
      {[](auto& o) { o.beta1 = -0.1; }, "beta1"},   {[](auto& o) { o.beta2 = 1; }, "beta2"},
      {[nan](auto& o) { o.beta2 = nan; }, "beta2"}, {[](auto& o) { o.lr = -1e-3; }, "lr"},
      {[inf](auto& o) { o.lr = inf; }, "lr"},       {[](auto& o) { o.weight_decay = -0.01; }, "weight_decay"},
  };
  ag::Tensord p = ag::Tensord::from({1, 2}, {1.0, -3.0}, true);
  for (const auto& [set, key] : bad) {
    nn::AdamWOptions o;
    set(o);
    CAPTURE(key);
    const std::string want = "AdamW: " + key + " must be";
    CHECK_THROWS_WITH_AS(nn::AdamW<double>{o}, doctest::Contains(want.c_str()), ag::Error);
    CHECK_THROWS_WITH_AS((nn::AdamW<float>{{}, o}), doctest::Contains(want.c_str()), ag::Error);
    CHECK_THROWS_WITH_AS((nn::AdamW<double>{{{"p", p}}, o}), doctest::Contains(want.c_str()), ag::Error);
  }
  nn::AdamW<double> opt({{"p", p}});
  CHECK_THROWS_WITH_AS(opt.set_lr(std::numeric_limits<double>::quiet_NaN()), doctest::Contains("AdamW: lr must be"),
                       ag::Error);
  CHECK(opt.lr() == 1e-3);  // unchanged by the refused value
  opt.set_lr(0);            // the edges of the domain are taken
  nn::AdamWOptions edge;
  edge.beta1 = 0;
  edge.beta2 = 0;
  edge.weight_decay = 0;
  CHECK_NOTHROW(nn::AdamW<double>{edge});
}

TEST_CASE("schedules: step decay halves every N steps down to the floor / loss-weight ramp") {
  nn::StepDecay sd{1e-4, 0.5, 100, 1e-6};
  CHECK(sd(0) == 1e-4);
  CHECK(sd(99) == 1e-4);
  CHECK(sd(100) == doctest::Approx(5e-5));
  CHECK(sd(250) == doctest::Approx(2.5e-5));
  CHECK(sd(100000) == 1e-6);
  nn::AdamW<float> opt;
  sd.apply(opt, 300);
  CHECK(opt.lr() == doctest::Approx(1.25e-5));

  const nn::RampSchedule down{1.9, -0.2, 10, 1.0}, up{0.1, 0.2, 10, 1.0};  // the paper's lambda_c, lambda_w
  CHECK(down(0) == doctest::Approx(1.9));
  CHECK(up(0) == doctest::Approx(0.1));
  CHECK(down(15) == doctest::Approx(1.7));
  CHECK(up(15) == doctest::Approx(0.3));
  CHECK(down(100) == 1.0);
  CHECK(up(100) == 1.0);
  const nn::StepDecay bad{1e-4, 0.5, 0, 0};
  CHECK_THROWS_AS(bad(5), ag::Error);
}

// Gradient checks of the losses.
#include "tests/support/ag_test_util.hpp"

using namespace agt;

namespace {
constexpr double kTol = 1e-6;
}

TEST_CASE("loss: l1 and mse, gradients w.r.t. prediction and target") {
  const Tensord p = randn({6, 3}, 1), t = randn({6, 3}, 2);
  check_grad("l1_loss", kTol, [](auto& in) { return ag::l1_loss(in[0], in[1]); }, {p, t});
  check_grad("mse_loss", kTol, [](auto& in) { return ag::mse_loss(in[0], in[1]); }, {p, t});
  for (double s : {1e-3, 1e3}) {
    INFO("scale " << s);
    check_grad(
        "mse scaled", kTol, [](auto& in) { return ag::mse_loss(in[0], in[1]); },
        {randn({6, 3}, 3, s), randn({6, 3}, 4, s)});
    check_grad(
        "l1 scaled", kTol, [](auto& in) { return ag::l1_loss(in[0], in[1]); },
        {randn({6, 3}, 5, s), randn({6, 3}, 6, s)});
  }
}

TEST_CASE("loss: values, target without grad, shape mismatch") {
  const Tensord p = randn({4, 2}, 7), t = randn({4, 2}, 8);
  CHECK(ag::l1_loss(p, t).item() == doctest::Approx((p.mat() - t.mat()).cwiseAbs().mean()));
  CHECK(ag::mse_loss(p, t).item() == doctest::Approx((p.mat() - t.mat()).squaredNorm() / 8));
  Tensord pl = p.detach().set_requires_grad(true);
  ag::mse_loss(pl, t).backward();
  CHECK(pl.grad()[3] == doctest::Approx(2 * (p.data()[3] - t.data()[3]) / 8));
  CHECK_FALSE(t.has_grad());
  CHECK_THROWS_WITH_AS(ag::mse_loss(p, randn({2, 4}, 9)), doctest::Contains("mse_loss"), ag::Error);
  CHECK(max_abs_diff(ag::l1_loss(to_float(p), to_float(t)), ag::l1_loss(p, t)) < 1e-5);
}

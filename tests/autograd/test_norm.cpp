// Gradient checks of channel_norm and layer_norm, including equal rows.
#include "tests/support/ag_test_util.hpp"

using namespace agt;

namespace {
constexpr double kTol = 1e-6;
}

TEST_CASE("norm: channel_norm and layer_norm on random inputs") {
  const Tensord x = randn({7, 4}, 1, 2.0, 0.5);
  check_grad("channel_norm", kTol, [](auto& in) { return ag::channel_norm(in[0]); }, {x});
  check_grad("layer_norm", kTol, [](auto& in) { return ag::layer_norm(in[0]); }, {x});
  for (double s : {1e-3, 1e3}) {
    INFO("scale " << s);
    // eps = 1e-5 against a variance of ~1e-6 at scale 1e-3: still a smooth function.
    check_grad(
        "channel_norm scaled", kTol, [](auto& in) { return ag::channel_norm(in[0]); }, {randn({7, 4}, 2, s)},
        step_for_scale(s));
    check_grad(
        "layer_norm scaled", kTol, [](auto& in) { return ag::layer_norm(in[0]); }, {randn({7, 4}, 3, s)},
        step_for_scale(s));
  }
}

TEST_CASE("norm: values (biased variance, eps inside the sqrt)") {
  const Tensord x = randn({6, 3}, 4);
  const Tensord c = ag::channel_norm(x, 1e-5), l = ag::layer_norm(x, 1e-5);
  const Eigen::MatrixXd m = x.mat();
  for (int j = 0; j < 3; ++j) {
    const double mu = m.col(j).mean(), var = (m.col(j).array() - mu).square().mean();
    CHECK(c.at(2, j) == doctest::Approx((m(2, j) - mu) / std::sqrt(var + 1e-5)));
  }
  const double mu = m.row(1).mean(), var = (m.row(1).array() - mu).square().mean();
  CHECK(l.at(1, 2) == doctest::Approx((m(1, 2) - mu) / std::sqrt(var + 1e-5)));
}

TEST_CASE("norm: equal rows give 0 output and finite gradients") {
  // all rows equal: channel_norm sees zero variance in every column
  std::vector<double> v;
  for (int r = 0; r < 5; ++r) v.insert(v.end(), {0.3, -1.2, 7.0});
  const Tensord x = Tensord::from({5, 3}, v);
  check_grad("channel_norm equal rows", kTol, [](auto& in) { return ag::channel_norm(in[0]); }, {x});
  const Tensord y = ag::channel_norm(x);
  CHECK(max_abs(y) < 1e-9);
  Tensord xl = x.detach().set_requires_grad(true);
  sum(ag::channel_norm(xl) * randn({5, 3}, 5)).backward();
  CHECK(all_finite(xl.grad()));
  // equal entries within a row: layer_norm sees zero variance
  const Tensord e = Tensord::full({4, 6}, 2.5);
  check_grad("layer_norm equal rows", kTol, [](auto& in) { return ag::layer_norm(in[0]); }, {e});
  CHECK(max_abs(ag::layer_norm(e)) < 1e-9);
  Tensord el = e.detach().set_requires_grad(true);
  sum(ag::layer_norm(el) * randn({4, 6}, 6)).backward();
  CHECK(all_finite(el.grad()));
}

TEST_CASE("norm: large channel_norm is deterministic and matches a direct computation") {
  const Tensord x = randn({20000, 16}, 7, 3.0, 1.0);
  const Tensord a = ag::channel_norm(x), b = ag::channel_norm(x);
  CHECK(a.values() == b.values());
  const Eigen::MatrixXd m = x.mat();
  const Eigen::RowVectorXd mu = m.colwise().mean();
  const Eigen::RowVectorXd var = (m.rowwise() - mu).array().square().colwise().mean();
  double err = 0;
  for (int64_t r = 0; r < 20000; r += 997)
    for (int j = 0; j < 16; ++j)
      err = std::max(err, std::abs(a.at(r, j) - (m(r, j) - mu(j)) / std::sqrt(var(j) + 1e-5)));
  CHECK(err < 1e-12);
}

TEST_CASE("norm: float32 matches float64 within 1e-5") {
  const Tensord x = randn({300, 8}, 8);
  CHECK(max_abs_diff(ag::channel_norm(to_float(x)), ag::channel_norm(x)) < 1e-5);
  CHECK(max_abs_diff(ag::layer_norm(to_float(x)), ag::layer_norm(x)) < 1e-5);
}

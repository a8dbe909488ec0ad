// Gradient checks of the reductions.
#include "tests/support/ag_test_util.hpp"

using namespace agt;

namespace {
constexpr double kTol = 1e-6;  // linear ops
}

TEST_CASE("reduce: sum, mean, per row and per column") {
  const Tensord x = randn({5, 4}, 1);
  check_grad("sum", kTol, [](auto& in) { return ag::sum(in[0]); }, {x});
  check_grad("mean", kTol, [](auto& in) { return ag::mean(in[0]); }, {x});
  check_grad("sum_rows", kTol, [](auto& in) { return ag::sum_rows(in[0]); }, {x});
  check_grad("mean_rows", kTol, [](auto& in) { return ag::mean_rows(in[0]); }, {x});
  check_grad("sum_cols", kTol, [](auto& in) { return ag::sum_cols(in[0]); }, {x});
  check_grad("mean_cols", kTol, [](auto& in) { return ag::mean_cols(in[0]); }, {x});
}

TEST_CASE("reduce: values and shapes") {
  const Tensord x = randn({5, 4}, 2);
  CHECK(ag::sum(x).item() == doctest::Approx(x.mat().sum()).epsilon(1e-14));
  CHECK(ag::mean(x).item() == doctest::Approx(x.mat().mean()).epsilon(1e-14));
  const Tensord r = ag::mean_rows(x), c = ag::sum_cols(x);
  CHECK(r.shape() == ag::Shape{5, 1});
  CHECK(c.shape() == ag::Shape{1, 4});
  CHECK(r.at(3, 0) == doctest::Approx(x.mat().row(3).mean()));
  CHECK(c.at(0, 2) == doctest::Approx(x.mat().col(2).sum()));
}

TEST_CASE("reduce: complex sum and mean") {
  const Tensord re = randn({3, 4}, 3), im = randn({3, 4}, 4);
  check_grad("complex sum", kTol, [](auto& in) { return split(ag::sum(cplx(in[0], in[1]))); }, {re, im});
  check_grad("complex mean", kTol, [](auto& in) { return split(ag::mean(cplx(in[0], in[1]))); }, {re, im});
}

TEST_CASE("reduce: float32 matches float64 within 1e-5") {
  const Tensord x = randn({50, 8}, 5);
  CHECK(max_abs_diff(ag::mean(to_float(x)), ag::mean(x)) < 1e-5);
  CHECK(max_abs_diff(ag::sum_rows(to_float(x)), ag::sum_rows(x)) < 1e-5);
  CHECK(max_abs_diff(ag::mean_cols(to_float(x)), ag::mean_cols(x)) < 1e-5);
}

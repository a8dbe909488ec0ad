// Gradient checks of concat, slice and reshape.
#include "tests/support/ag_test_util.hpp"

using namespace agt;

namespace {
constexpr double kTol = 1e-6;  // copies: exact up to round-off
}

TEST_CASE("shape: concat_cols / concat_rows gradients and values") {
  const Tensord a = randn({4, 2}, 1), b = randn({4, 3}, 2), c = randn({1, 2}, 3);
  check_grad("concat_cols", kTol, [](auto& in) { return ag::concat_cols<double>({in[0], in[1], in[0]}); }, {a, b});
  check_grad("concat_rows", kTol, [](auto& in) { return ag::concat_rows<double>({in[0], in[1], in[0]}); }, {a, c});
  const Tensord cc = ag::concat_cols<double>({a, b});
  CHECK(cc.shape() == ag::Shape{4, 5});
  CHECK(cc.at(2, 1) == a.at(2, 1));
  CHECK(cc.at(3, 4) == b.at(3, 2));
  const Tensord cr = ag::concat_rows<double>({a, c});
  CHECK(cr.shape() == ag::Shape{5, 2});
  CHECK(cr.at(4, 1) == c.at(0, 1));
}

TEST_CASE("shape: slice_cols / slice_rows / reshape gradients and values") {
  const Tensord x = randn({5, 6}, 4);
  check_grad("slice_cols", kTol, [](auto& in) { return ag::slice_cols(in[0], 1, 4); }, {x});
  check_grad("slice_rows", kTol, [](auto& in) { return ag::slice_rows(in[0], 2, 5); }, {x});
  check_grad("reshape", kTol, [](auto& in) { return ag::reshape(in[0], {3, 10}); }, {x});
  // two overlapping slices accumulate into the same input
  check_grad("overlapping slices", kTol,
             [](auto& in) { return ag::slice_cols(in[0], 0, 4) * ag::slice_cols(in[0], 2, 6); }, {x});
  const Tensord s = ag::slice_cols(x, 1, 4), r = ag::slice_rows(x, 2, 5);
  CHECK(s.shape() == ag::Shape{5, 3});
  CHECK(s.at(4, 2) == x.at(4, 3));
  CHECK(r.shape() == ag::Shape{3, 6});
  CHECK(r.at(0, 5) == x.at(2, 5));
  CHECK(ag::reshape(x, {30, 1}).at(13, 0) == x.at(2, 1));
}

TEST_CASE("shape: errors name the op and the shapes") {
  const Tensord a = randn({4, 2}, 1), b = randn({3, 2}, 2);
  CHECK_THROWS_WITH_AS(ag::concat_cols<double>({a, b}), doctest::Contains("concat_cols"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::concat_cols<double>({a, b}), doctest::Contains("[3 x 2]"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::concat_rows<double>({a, randn({4, 3}, 3)}), doctest::Contains("[4 x 3]"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::slice_cols(a, 1, 3), doctest::Contains("slice_cols"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::slice_rows(a, 3, 2), doctest::Contains("slice_rows"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::reshape(a, {3, 3}), doctest::Contains("[3 x 3]"), ag::Error);
}

TEST_CASE("shape: complex concat and slice") {
  const Tensord re = randn({3, 4}, 5), im = randn({3, 4}, 6);
  check_grad("complex slice+concat", kTol,
             [](auto& in) {
               const auto z = cplx(in[0], in[1]);
               return split(ag::concat_rows<std::complex<double>>(
                   {ag::slice_cols(z, 1, 3), ag::reshape(ag::slice_rows(z, 0, 1), {2, 2})}));
             },
             {re, im});
}

// conv2d_3x3, avg_pool2x2, max_pool2x2: values against direct loops, float64 gradient checks.
#include "tests/support/ag_test_util.hpp"

using namespace agt;

namespace {
constexpr double kTol = 1e-6;  // conv and pooling are (piecewise) linear: central differences are exact up to round-off

// Direct definition: out[n,o,y,x] = b[o] + sum_{c,ky,kx} w[o,c,ky,kx] x[n,c,y+ky-1,x+kx-1].
Tensord conv_ref(const Tensord& x, const Tensord& w, const Tensord* b) {
  const int64_t N = x.size(0), C = x.size(1), H = x.size(2), W = x.size(3), O = w.size(0);
  Tensord out = Tensord::zeros({N, O, H, W});
  for (int64_t n = 0; n < N; ++n)
    for (int64_t o = 0; o < O; ++o)
      for (int64_t y = 0; y < H; ++y)
        for (int64_t xx = 0; xx < W; ++xx) {
          double s = b ? b->data()[o] : 0.0;
          for (int64_t c = 0; c < C; ++c)
            for (int64_t ky = 0; ky < 3; ++ky)
              for (int64_t kx = 0; kx < 3; ++kx) {
                const int64_t sy = y + ky - 1, sx = xx + kx - 1;
                if (sy < 0 || sy >= H || sx < 0 || sx >= W) continue;
                s += w.data()[((o * C + c) * 3 + ky) * 3 + kx] * x.data()[((n * C + c) * H + sy) * W + sx];
              }
          out.data()[((n * O + o) * H + y) * W + xx] = s;
        }
  return out;
}

double max_diff(const Tensord& a, const Tensord& b) {
  REQUIRE(a.shape() == b.shape());
  double m = 0;
  for (int64_t i = 0; i < a.numel(); ++i) m = std::max(m, std::abs(a.data()[i] - b.data()[i]));
  return m;
}
}  // namespace

TEST_CASE("conv2d_3x3: values match the direct definition (several shapes, float and double)") {
  const std::vector<ag::Shape> shapes = {{1, 1, 1, 1}, {2, 3, 5, 6}, {1, 4, 2, 7}, {3, 2, 8, 3}};
  unsigned seed = 10;
  for (const auto& s : shapes) {
    INFO("input " << ag::shape_str(s));
    const Tensord x = randn(s, seed++), w = randn({5, s[1], 3, 3}, seed++), b = randn({5}, seed++);
    CHECK(max_diff(ag::conv2d_3x3(x, w, b), conv_ref(x, w, &b)) < 1e-12);
    CHECK(max_diff(ag::conv2d_3x3(x, w, Tensord()), conv_ref(x, w, nullptr)) < 1e-12);
    const Tensorf yf = ag::conv2d_3x3(to_float(x), to_float(w), to_float(b));
    CHECK(max_abs_diff(yf, conv_ref(x, w, &b)) < 1e-4 * (1 + max_abs(conv_ref(x, w, &b))));
  }
}

TEST_CASE("conv2d_3x3: gradient check (input, weight, bias), also at scales 1e-3 and 1e3") {
  const auto f = [](auto& in) { return ag::conv2d_3x3(in[0], in[1], in[2]); };
  check_grad("conv", kTol, f, {randn({2, 3, 5, 6}, 1), randn({4, 3, 3, 3}, 2), randn({4}, 3)});
  check_grad("conv no bias", kTol, [](auto& in) { return ag::conv2d_3x3(in[0], in[1], Tensord()); },
             {randn({1, 2, 4, 3}, 4), randn({3, 2, 3, 3}, 5)});
  check_grad("conv 1x1 image", kTol, f, {randn({1, 2, 1, 1}, 6), randn({2, 2, 3, 3}, 7), randn({2}, 8)});
  // One operand scaled at a time and no bias: otherwise L is dominated by a term of another
  // scale than the gradients checked, and the central difference's round-off (1e-16 L / h)
  // would exceed the tolerance (the bias is checked unscaled above).
  const auto fnb = [](auto& in) { return ag::conv2d_3x3(in[0], in[1], Tensord()); };
  for (double s : {1e-3, 1e3}) {
    INFO("scale " << s);
    check_grad("conv scaled input", kTol, fnb, {randn({1, 2, 4, 5}, 9, s), randn({3, 2, 3, 3}, 10)});
    check_grad("conv scaled weight", kTol, fnb, {randn({1, 2, 4, 5}, 9), randn({3, 2, 3, 3}, 10, s)});
  }
}

TEST_CASE("conv2d_3x3: a chain conv -> avg pool -> conv accumulates gradients correctly") {
  const auto f = [](auto& in) {
    return ag::conv2d_3x3(ag::avg_pool2x2(ag::conv2d_3x3(in[0], in[1], in[2])), in[3], Tensord());
  };
  check_grad("conv-pool-conv", kTol, f,
             {randn({2, 2, 6, 4}, 12), randn({3, 2, 3, 3}, 13), randn({3}, 14), randn({2, 3, 3, 3}, 15)});
}

TEST_CASE("conv2d_3x3: shape errors name the op and the shapes") {
  const Tensord x = randn({1, 3, 4, 4}, 1), w = randn({2, 4, 3, 3}, 2);
  CHECK_THROWS_WITH_AS(ag::conv2d_3x3(x, w, Tensord()), doctest::Contains("conv2d_3x3"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::conv2d_3x3(x, w, Tensord()), doctest::Contains("[2 x 4 x 3 x 3]"), ag::Error);
  CHECK_THROWS_AS(ag::conv2d_3x3(randn({3, 4}, 3), w, Tensord()), ag::Error);
  CHECK_THROWS_AS(ag::conv2d_3x3(randn({1, 4, 4, 4}, 3), w, randn({3}, 4)), ag::Error);
}

TEST_CASE("avg_pool2x2: values, odd sizes drop the last row/column, gradient check") {
  const Tensord x = randn({2, 3, 5, 7}, 21);
  const Tensord y = ag::avg_pool2x2(x);
  REQUIRE(y.shape() == ag::Shape{2, 3, 2, 3});
  double m = 0;
  for (int64_t p = 0; p < 6; ++p)
    for (int64_t i = 0; i < 2; ++i)
      for (int64_t j = 0; j < 3; ++j) {
        const double* s = x.data() + p * 35 + 2 * i * 7 + 2 * j;
        const double e = 0.25 * (s[0] + s[1] + s[7] + s[8]);
        m = std::max(m, std::abs(e - y.data()[(p * 2 + i) * 3 + j]));
      }
  CHECK(m < 1e-15);
  check_grad("avg pool", kTol, [](auto& in) { return ag::avg_pool2x2(in[0]); }, {x});
  check_grad("avg pool 1e3", kTol, [](auto& in) { return ag::avg_pool2x2(in[0]); }, {randn({1, 2, 4, 4}, 22, 1e3)});
  CHECK_THROWS_WITH_AS(ag::avg_pool2x2(randn({1, 1, 1, 4}, 1)), doctest::Contains("avg_pool2x2"), ag::Error);
}

TEST_CASE("max_pool2x2: values, gradient check, ties go to the first element, NaN propagates") {
  const Tensord x = randn({2, 2, 6, 5}, 31);
  const Tensord y = ag::max_pool2x2(x);
  REQUIRE(y.shape() == ag::Shape{2, 2, 3, 2});
  double m = 0;
  for (int64_t p = 0; p < 4; ++p)
    for (int64_t i = 0; i < 3; ++i)
      for (int64_t j = 0; j < 2; ++j) {
        const double* s = x.data() + p * 30 + 2 * i * 5 + 2 * j;
        const double e = std::max({s[0], s[1], s[5], s[6]});
        m = std::max(m, std::abs(e - y.data()[(p * 3 + i) * 2 + j]));
      }
  CHECK(m == 0.0);
  // Random normal entries: the 2x2 maxima are separated by far more than the step 1e-6.
  check_grad("max pool", kTol, [](auto& in) { return ag::max_pool2x2(in[0]); }, {x});

  Tensord t = Tensord::from({1, 1, 2, 2}, {1.0, 3.0, 3.0, 2.0}, true);
  ag::sum(ag::max_pool2x2(t)).backward();
  CHECK(t.grad() == std::vector<double>{0, 1, 0, 0});

  const Tensord n = Tensord::from({1, 1, 2, 2}, {1.0, NAN, 5.0, 2.0});
  CHECK(std::isnan(ag::max_pool2x2(n).item()));
}

TEST_CASE("conv/pool: no graph under NoGradGuard, frozen weights get no gradient") {
  Tensord x = randn({1, 2, 4, 4}, 41);
  x.set_requires_grad(true);
  const Tensord w = randn({3, 2, 3, 3}, 42), b = randn({3}, 43);
  {
    ag::NoGradGuard ng;
    CHECK_FALSE(ag::max_pool2x2(ag::conv2d_3x3(x, w, b)).requires_grad());
  }
  ag::sum(ag::avg_pool2x2(ag::conv2d_3x3(x, w, b))).backward();
  CHECK(x.has_grad());
  CHECK_FALSE(w.has_grad());
  CHECK_FALSE(b.has_grad());
}

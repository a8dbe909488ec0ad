// The VGG cosine loss (nn/feature_loss.cpp) at the ends of the float range: the cosine is
// scale-free, so inputs scaled by s give the same value and gradients scaled by 1/s, exactly
// to rounding, from mm scale up to near the largest float (the plain sums a.a and a.b used to
// overflow: NaN beyond ~1e19 in float32 and ~1e154 in float64).
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "nn/feature_loss.hpp"
#include "tests/support/ag_test_util.hpp"

#include <cmath>
#include <limits>

namespace {

using namespace agt;

// Values of t times s, as a leaf requiring grad (float or double).
template <class T> ag::Tensor<T> scaled_leaf(const Tensord& t, double s) {
  std::vector<T> v;
  for (double x : t.values()) v.push_back(static_cast<T>(x * s));
  return ag::Tensor<T>::from(t.shape(), v, true);
}

// 1 - mean cos over the pixels, in long double, with no eps (every test vector is far above it).
long double exact_loss(const Tensord& a, const Tensord& b) {
  const int64_t N = a.size(0), C = a.size(1), HW = a.size(2) * a.size(3);
  long double sum = 0;
  for (int64_t n = 0; n < N; ++n)
    for (int64_t p = 0; p < HW; ++p) {
      long double ab = 0, aa = 0, bb = 0;
      for (int64_t c = 0; c < C; ++c) {
        const long double x = a.data()[(n * C + c) * HW + p], y = b.data()[(n * C + c) * HW + p];
        ab += x * y, aa += x * x, bb += y * y;
      }
      sum += ab / std::sqrt(aa * bb);
    }
  return 1 - sum / static_cast<long double>(N * HW);
}

}  // namespace

TEST_CASE("cosine_distance_channels: scale-free value and gradients from 1e-3 to near the largest float") {
  const Tensord a = randn({2, 6, 2, 3}, 31), b = randn({2, 6, 2, 3}, 32);
  const double exact = static_cast<double>(exact_loss(a, b));
  // Unit-scale gradients of the float64 loss, the reference for the scaled ones (x s).
  ag::Tensord a1 = scaled_leaf<double>(a, 1), b1 = scaled_leaf<double>(b, 1);
  nn::cosine_distance_channels(a1, b1).backward();
  double gmax = 0;
  for (double g : a1.grad()) gmax = std::max(gmax, std::abs(g));
  REQUIRE(gmax > 0);

  auto run = [&](auto zero, double s, double tol) {
    using T = decltype(zero);
    CAPTURE(s);
    ag::Tensor<T> as = scaled_leaf<T>(a, s), bs = scaled_leaf<T>(b, s);
    const ag::Tensor<T> l = nn::cosine_distance_channels(as, bs);
    REQUIRE(std::isfinite(double(l.item())));
    CHECK(std::abs(double(l.item()) - exact) < tol);
    l.backward();
    for (size_t i = 0; i < a1.grad().size(); ++i) {
      CAPTURE(i);
      // d/d(a s) = (d/da) / s: the scaled gradient times s is the unit one.
      CHECK(std::abs(double(as.grad()[i]) * s - a1.grad()[i]) < tol * gmax);
      CHECK(std::abs(double(bs.grad()[i]) * s - b1.grad()[i]) < tol * gmax);
    }
  };
  for (double s : {1e-3, 1e3, 1e160, 1e300}) run(0.0, s, 1e-13);
  for (double s : {1e-3, 1e3, 1e20, 1e36}) run(0.0f, s, 1e-5);

  // And float64 central differences at 1e200, both inputs scaled (tolerance 1e-5 as the
  // unit-scale check in test_vgg.cpp, for the same round-off).
  const auto r =
      ag::gradcheck([](const std::vector<ag::Tensord>& in) { return nn::cosine_distance_channels(in[0], in[1]); },
                    {ag::mul_scalar(a, 1e200).detach(), ag::mul_scalar(b, 1e200).detach()});
  CHECK_MESSAGE(r.max_rel_error < 1e-5, r.report());
}

TEST_CASE("cosine_distance_channels: subnormal vectors stay finite and eps must be finite and positive") {
  const Tensord b = randn({1, 4, 2, 2}, 33);
  // |a| ~ 1e-310 is far below eps: na = eps, and cos = a.b / (eps |b|) ~ 1e-302, so L = 1.
  ag::Tensord tiny = scaled_leaf<double>(randn({1, 4, 2, 2}, 34), 1e-310), bb = scaled_leaf<double>(b, 1);
  const ag::Tensord l = nn::cosine_distance_channels(tiny, bb);
  CHECK(l.item() == 1.0);
  l.backward();
  for (double g : tiny.grad()) CHECK(std::isfinite(g));
  for (double g : bb.grad()) CHECK(std::isfinite(g));
  for (double eps : {0.0, -1e-8, std::numeric_limits<double>::quiet_NaN()})
    CHECK_THROWS_WITH_AS(nn::cosine_distance_channels(b, b, eps), doctest::Contains("eps"), ag::Error);
}

// Gradient checks of complex_from, real, imag and modulus.
#include "tests/support/ag_test_util.hpp"

#include <complex>
#include <limits>
#include <vector>

using namespace agt;
using ag::Tensorcd;

namespace {
constexpr double kTol = 1e-6;
}

TEST_CASE("complex: from / real / imag / modulus gradients") {
  const Tensord re = randn({4, 3}, 1), im = randn({4, 3}, 2);
  check_grad("complex_from -> real, imag", kTol, [](auto& in) { return split(cplx(in[0], in[1])); }, {re, im});
  check_grad("complex_from_real", kTol,
             [](auto& in) { return split(ag::complex_from_real(in[0]) * cplx(in[1], in[1])); }, {re, im});
  check_grad("modulus", kTol, [](auto& in) { return ag::modulus(cplx(in[0], in[1])); }, {re, im});
  // a holomorphic chain: |z^2 + z| via mul/add (conj(f') convention)
  check_grad("modulus of z^2 + z", kTol,
             [](auto& in) {
               const auto z = cplx(in[0], in[1]);
               return ag::modulus(z * z + z);
             },
             {re, im});
  for (double s : {1e-3, 1e3}) {
    INFO("scale " << s);
    check_grad("modulus scaled", kTol, [](auto& in) { return ag::modulus(cplx(in[0], in[1])); },
               {randn({4, 3}, 3, s), randn({4, 3}, 4, s)});
  }
}

TEST_CASE("complex: values and the gradient convention grad = dL/dRe + i dL/dIm") {
  Tensorcd z = Tensorcd::from({1, 2}, {{3.0, 4.0}, {0.0, 0.0}}, true);
  const Tensord m = ag::modulus(z);
  CHECK(m.at(0, 0) == 5.0);
  CHECK(m.at(0, 1) == 0.0);
  sum(m).backward();
  CHECK(std::abs(z.grad()[0] - std::complex<double>(0.6, 0.8)) < 1e-15);
  CHECK(z.grad()[1] == std::complex<double>(0, 0));  // grad 0 at z = 0
  Tensorcd w = Tensorcd::from({1, 1}, {{1.0, 2.0}}, true);
  sum(ag::imag(w * w)).backward();  // Im(w^2) = 2ab: d/da = 2b = 4, d/db = 2a = 2
  CHECK(std::abs(w.grad()[0] - std::complex<double>(4, 2)) < 1e-15);
  CHECK_THROWS_WITH_AS(ag::complex_from(randn({2, 2}, 1), randn({2, 3}, 2)), doctest::Contains("complex_from"),
                       ag::Error);
}

TEST_CASE("complex: float32 matches float64 within 1e-5") {
  const Tensord re = randn({10, 3}, 5), im = randn({10, 3}, 6);
  const auto zd = cplx(re, im);
  const auto zf = ag::complex_from(to_float(re), to_float(im));
  CHECK(max_abs_diff(ag::modulus(zf * zf), ag::modulus(zd * zd)) < 1e-5);
  CHECK(max_abs_diff(ag::imag(zf * zf), ag::imag(zd * zd)) < 1e-5);
}

TEST_CASE("complex: modulus gradient is the unit z / |z| at subnormal and near-overflow moduli") {
  // g / |z| overflows once |z| is subnormal (1 / 3e-310 > the largest double), which made the
  // gradient inf or NaN where the exact value is a unit complex number.
  auto run = [](auto zero, double s) {
    using R = decltype(zero);
    using C = std::complex<R>;
    CAPTURE(s);
    const Tensord re = rand_signed({3, 4}, 41, 0.2, 1), im = randn({3, 4}, 42);
    std::vector<C> v;
    for (size_t i = 0; i < re.values().size(); ++i) v.emplace_back(R(re.values()[i] * s), R(im.values()[i] * s));
    ag::Tensor<C> z = ag::Tensor<C>::from({3, 4}, v, true);
    ag::sum(ag::modulus(z)).backward();
    for (size_t i = 0; i < v.size(); ++i) {
      CAPTURE(i);
      const long double a = v[i].real(), b = v[i].imag(), m = std::sqrt(a * a + b * b);
      // A few rounding units, plus the rounding of a subnormal |z| itself (spacing
      // denorm_min, relative denorm_min / |z|: 1.6e-14 at 3e-310).
      const double tol = 4 * std::numeric_limits<R>::epsilon() + 2 * double(std::numeric_limits<R>::denorm_min() / m);
      CHECK(std::abs(double(z.grad()[i].real() - a / m)) < tol);
      CHECK(std::abs(double(z.grad()[i].imag() - b / m)) < tol);
    }
  };
  for (double s : {3e-310, 1e-300, 1.0, 1e307}) run(0.0, s);
  for (double s : {3e-40, 1e-30, 1.0, 1e37}) run(0.0f, s);
}

// Gradient checks of the fused WIRE activation, including large arguments.
#include "tests/support/ag_test_util.hpp"

using namespace agt;
using ag::Tensorcd;

namespace {
constexpr double kTol = 1e-6;
Tensord wire_split(const std::vector<Tensord>& in, double w0, double s0) {
  return split(ag::wire(cplx(in[0], in[1]), w0, s0));
}
}  // namespace

TEST_CASE("wire: gradient and value on moderate inputs") {
  const Tensord a = randn({5, 4}, 1, 0.1), b = randn({5, 4}, 2, 0.1);
  check_grad("wire default", kTol, [](auto& in) { return wire_split(in, 5, 10); }, {a, b});
  check_grad("wire w0=30 s0=1", kTol, [](auto& in) { return wire_split(in, 30, 1); }, {a, b});
  const Tensorcd y = ag::wire(cplx(a, b));
  for (int64_t i = 0; i < y.numel(); ++i) {
    const std::complex<double> x(a.data()[i], b.data()[i]);
    const std::complex<double> e = std::exp(std::complex<double>(0, 5) * x - 100.0 * std::norm(x));
    CHECK(std::abs(y.data()[i] - e) < 1e-14);
  }
}

TEST_CASE("wire: |imag| > 20 with non-negligible values (s0 = 0.5)") {
  // Re(E) = -5 b - 0.25 (a^2 + b^2) is O(1) for b near -20 but exp(-omega0 b) alone is e^100:
  // checks the formula where naive evaluation would lose digits.
  const Tensord a = randn({4, 3}, 3, 0.5), b = randu({4, 3}, 4, -21.0, -19.5);
  check_grad("wire imag ~ -20", kTol, [](auto& in) { return wire_split(in, 5, 0.5); }, {a, b});
  // positive side: Re(E) ~ -23, values ~ 1e-10, scaled up so the check is not judged
  // against the absolute floor of 1e-12.
  const Tensord bp = randu({4, 3}, 5, 20.0, 25.0);
  check_grad("wire imag > 20", kTol, [](auto& in) { return wire_split(in, 1, 0.05) * 1e10; }, {a, bp});
}

TEST_CASE("wire: large arguments (|imag| > 20, real 1e3) give finite values and gradients -> 0") {
  std::vector<double> re{1e3, -1e3, 0.1, 1e3, 0.0, -0.3}, im{0.0, 25.0, -25.0, -1e3, -21.0, 21.0};
  const Tensord a = Tensord::from({2, 3}, re), b = Tensord::from({2, 3}, im);
  // default omega0 = 5, s0 = 10: the exact values are below 1e-4000, i.e. 0 in double
  check_grad("wire large args", kTol, [](auto& in) { return wire_split(in, 5, 10); }, {a, b});
  Tensord al = a.detach().set_requires_grad(true), bl = b.detach().set_requires_grad(true);
  const Tensord y = wire_split({al, bl}, 5, 10);
  CHECK(all_finite(y.values()));
  CHECK(max_abs(y) == 0.0);
  sum(y).backward();
  CHECK(all_finite(al.grad()));
  CHECK(all_finite(bl.grad()));
  CHECK(max_abs(Tensord::from({2, 3}, al.grad())) == 0.0);
  CHECK(max_abs(Tensord::from({2, 3}, bl.grad())) == 0.0);
  // float32: exp(-omega0 b) alone overflows for b = -25 (e^125 > FLT_MAX); the fused sum does not
  ag::Tensorcf zf = ag::Tensorcf::from({1, 3}, {{0.0f, -25.0f}, {1e3f, -21.0f}, {1e3f, 0.0f}}, true);
  const ag::Tensorcf yf = ag::wire(zf, 5.0f, 10.0f);
  for (const auto& v : yf.values()) CHECK((std::isfinite(v.real()) && std::isfinite(v.imag())));
  ag::sum(ag::modulus(yf) + ag::real(yf)).backward();
  for (const auto& v : zf.grad()) CHECK((std::isfinite(v.real()) && std::isfinite(v.imag())));
}

TEST_CASE("wire: float32 matches float64 within 1e-5") {
  const Tensord a = randn({10, 4}, 6, 0.2), b = randn({10, 4}, 7, 0.2);
  const auto yd = ag::wire(cplx(a, b));
  const auto yf = ag::wire(ag::complex_from(to_float(a), to_float(b)));
  CHECK(max_abs_diff(ag::real(yf), ag::real(yd)) < 1e-5);
  CHECK(max_abs_diff(ag::imag(yf), ag::imag(yd)) < 1e-5);
}

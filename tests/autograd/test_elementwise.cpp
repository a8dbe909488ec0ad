// Gradient checks of the elementwise ops: binary ops with broadcasting, unary math, atan2
// and sqrt at their extremes, complex arithmetic, float32 vs float64.
#include "tests/support/ag_test_util.hpp"

using namespace agt;
using ag::Tensorcd;

namespace {
constexpr double kTol = 1e-6;  // smooth inputs, central differences in float64
}

TEST_CASE("elementwise: binary ops with same shape and row/col/scalar broadcast") {
  const ag::Shape full{5, 4};
  const std::vector<std::pair<const char*, ag::Shape>> shapes{
      {"same", {5, 4}}, {"row [1 x C]", {1, 4}}, {"col [R x 1]", {5, 1}}, {"scalar [1 x 1]", {1, 1}}};
  for (const auto& [name, sb] : shapes) {
    const Tensord a = randn(full, 1), b = randn(sb, 2);
    const Tensord bpos = randu(sb, 3, 0.5, 2.0);  // divisor away from 0
    check_grad(std::string("add ") + name, kTol, [](auto& in) { return in[0] + in[1]; }, {a, b});
    check_grad(std::string("sub ") + name, kTol, [](auto& in) { return in[0] - in[1]; }, {a, b});
    check_grad(std::string("mul ") + name, kTol, [](auto& in) { return in[0] * in[1]; }, {a, b});
    check_grad(std::string("div ") + name, kTol, [](auto& in) { return in[0] / in[1]; }, {a, bpos});
    // broadcast operand on the left
    check_grad(std::string("mul left ") + name, kTol, [](auto& in) { return in[1] * in[0]; }, {a, b});
    check_grad(std::string("div left ") + name, kTol, [](auto& in) { return in[1] / in[0]; },
               {randu(full, 4, 0.5, 2.0), b});
  }
}

TEST_CASE("elementwise: broadcast values are right") {
  const Tensord a = randn({3, 2}, 5), r = randn({1, 2}, 6), c = randn({3, 1}, 7);
  const Tensord ar = a + r, ac = a * c;
  for (int64_t i = 0; i < 3; ++i)
    for (int64_t j = 0; j < 2; ++j) {
      CHECK(ar.at(i, j) == doctest::Approx(a.at(i, j) + r.at(0, j)).epsilon(1e-15));
      CHECK(ac.at(i, j) == doctest::Approx(a.at(i, j) * c.at(i, 0)).epsilon(1e-15));
    }
}

TEST_CASE("elementwise: shape mismatch names the op and both shapes") {
  const Tensord a = randn({3, 4}, 1), b = randn({2, 4}, 2);
  CHECK_THROWS_AS(add(a, b), ag::Error);
  try {
    mul(a, b);
    FAIL("mul of [3 x 4] and [2 x 4] did not throw");
  } catch (const ag::Error& e) {
    const std::string m = e.what();
    CHECK(m.find("mul") != std::string::npos);
    CHECK(m.find("[3 x 4]") != std::string::npos);
    CHECK(m.find("[2 x 4]") != std::string::npos);
  }
}

TEST_CASE("elementwise: neg, add_scalar, mul_scalar") {
  const Tensord a = randn({4, 3}, 11);
  check_grad("neg", kTol, [](auto& in) { return -in[0]; }, {a});
  check_grad("add_scalar", kTol, [](auto& in) { return in[0] + 2.5; }, {a});
  check_grad("sub scalar", kTol, [](auto& in) { return in[0] - 2.5; }, {a});
  check_grad("mul_scalar", kTol, [](auto& in) { return -1.5 * in[0]; }, {a});
}

TEST_CASE("elementwise: unary math on random inputs") {
  const Tensord x = randn({6, 5}, 21);
  const Tensord xpos = randu({6, 5}, 22, 0.2, 3.0);
  check_grad("exp", kTol, [](auto& in) { return ag::exp(in[0]); }, {x});
  check_grad("log", kTol, [](auto& in) { return ag::log(in[0]); }, {xpos});
  check_grad("sqrt", kTol, [](auto& in) { return ag::sqrt(in[0]); }, {xpos});
  check_grad("sin", kTol, [](auto& in) { return ag::sin(in[0]); }, {x});
  check_grad("cos", kTol, [](auto& in) { return ag::cos(in[0]); }, {x});
  check_grad("tanh", kTol, [](auto& in) { return ag::tanh(in[0]); }, {x});
  check_grad("abs", kTol, [](auto& in) { return ag::abs(in[0]); }, {x});
  check_grad("square", kTol, [](auto& in) { return ag::square(in[0]); }, {x});
  check_grad("pow 3", kTol, [](auto& in) { return ag::pow(in[0], 3.0); }, {x});
  check_grad("pow 0.5", kTol, [](auto& in) { return ag::pow(in[0], 0.5); }, {xpos});
  check_grad("pow -1.5", kTol, [](auto& in) { return ag::pow(in[0], -1.5); }, {xpos});
  check_grad("relu", kTol, [](auto& in) { return ag::relu(in[0]); }, {x});
  check_grad("leaky_relu", kTol, [](auto& in) { return ag::leaky_relu(in[0], 0.02); }, {x});
  check_grad("sigmoid", kTol, [](auto& in) { return ag::sigmoid(in[0]); }, {x});
  check_grad("clamp", kTol, [](auto& in) { return ag::clamp(in[0], -0.5, 0.7); }, {x});
}

TEST_CASE("elementwise: unary values match std") {
  const Tensord x = randn({3, 3}, 23);
  const Tensord r = ag::relu(x), l = ag::leaky_relu(x, 0.02), s = ag::sigmoid(x), c = ag::clamp(x, -0.5, 0.7);
  for (int64_t i = 0; i < x.numel(); ++i) {
    const double v = x.data()[i];
    CHECK(r.data()[i] == std::max(v, 0.0));
    CHECK(l.data()[i] == doctest::Approx(v > 0 ? v : 0.02 * v));
    CHECK(s.data()[i] == doctest::Approx(1 / (1 + std::exp(-v))));
    CHECK(c.data()[i] == std::min(std::max(v, -0.5), 0.7));
  }
  // gradients outside the clamp range and of relu on negatives are exactly 0
  Tensord y = randn({1, 4}, 24);
  y.values() = {-2.0, -0.1, 0.3, 2.0};
  y.set_requires_grad(true);
  sum(ag::clamp(y, -0.5, 0.7)).backward();
  CHECK(y.grad() == std::vector<double>{0, 1, 1, 0});
}

TEST_CASE("elementwise: sqrt near 0 (small positive)") {
  // x in [1e-6, 1e-5]: gradcheck's step is relative to the input's size (h = 1e-6 * max x
  // ~ 1e-11), so it does not cross 0; truncation error (h/x)^2 < 1e-10.
  check_grad(
      "sqrt near 0", kTol, [](auto& in) { return ag::sqrt(in[0]); }, {randu({4, 4}, 31, 1e-6, 1e-5)});
  check_grad(
      "log near 0", kTol, [](auto& in) { return ag::log(in[0]); }, {randu({4, 4}, 32, 1e-6, 1e-5)});
}

TEST_CASE("elementwise: atan2 on random inputs, near 0 and near pi") {
  check_grad("atan2 random", kTol, [](auto& in) { return ag::atan2(in[0], in[1]); },
             {randn({5, 4}, 41), randn({5, 4}, 42)});
  // near 0: y -> 0 (both signs), x > 0
  check_grad("atan2 near 0", kTol, [](auto& in) { return ag::atan2(in[0], in[1]); },
             {rand_signed({5, 4}, 43, 1e-8, 1e-6), randu({5, 4}, 44, 0.5, 2.0)});
  // near +-pi: y -> 0 (both signs), x < 0. |y| >= 1e-3 so that y +- h never crosses the
  // branch cut at y = 0 (where the value jumps by 2 pi). Values ~pi carry an absolute
  // round-off of ~4e-16 while d/dx ~ y/x^2 is ~1e-3: a step of 1e-4 of each input's size
  // (h <= 1e-6 for y, 2e-4 for x, truncation error (h/x)^2 ~ 1e-8) keeps that round-off
  // below the 1e-6 tolerance.
  ag::GradCheckOptions near_pi;
  near_pi.step = 1e-4;
  check_grad(
      "atan2 near pi", kTol, [](auto& in) { return ag::atan2(in[0], in[1]); },
      {rand_signed({5, 4}, 45, 1e-3, 1e-2), randu({5, 4}, 46, -2.0, -0.5)}, near_pi);
  // exactly on the cut and at the origin: values +-pi and 0, gradients finite
  Tensord y = Tensord::from({1, 4}, {0.0, -0.0, 1e-300, 0.0}, true);
  Tensord x = Tensord::from({1, 4}, {-1.0, -1.0, -1.0, 0.0}, true);
  const Tensord a = ag::atan2(y, x);
  CHECK(a.data()[0] == doctest::Approx(M_PI));
  CHECK(a.data()[1] == doctest::Approx(-M_PI));
  CHECK(a.data()[3] == 0.0);
  sum(a).backward();
  CHECK(all_finite(y.grad()));
  CHECK(all_finite(x.grad()));
  CHECK(y.grad()[0] == doctest::Approx(-1.0));  // d/dy atan2(y, x) = x / (x^2 + y^2)
  CHECK(y.grad()[3] == 0.0);                    // (0, 0) taken as 0
  CHECK(x.grad()[3] == 0.0);
}

TEST_CASE("elementwise: inputs scaled by 1e-3 and 1e3") {
  for (double s : {1e-3, 1e3}) {
    INFO("scale " << s);
    const ag::GradCheckOptions opt;  // gradcheck's step is relative to the input's size
    const Tensord a = randn({4, 3}, 51, s), b = randn({4, 3}, 52, s);
    check_grad(
        "mul scaled", kTol, [](auto& in) { return in[0] * in[1]; }, {a, b}, opt);
    check_grad(
        "div scaled", kTol, [](auto& in) { return in[0] / in[1]; }, {a, randu({4, 3}, 53, s, 2 * s)}, opt);
    check_grad(
        "atan2 scaled", kTol, [](auto& in) { return ag::atan2(in[0], in[1]); }, {a, b}, opt);
    check_grad(
        "sqrt scaled", kTol, [](auto& in) { return ag::sqrt(in[0]); }, {randu({4, 3}, 54, s, 3 * s)}, opt);
    check_grad(
        "log scaled", kTol, [](auto& in) { return ag::log(in[0]); }, {randu({4, 3}, 55, s, 3 * s)}, opt);
    check_grad(
        "tanh scaled", kTol, [s](auto& in) { return ag::tanh(in[0] * (1.0 / s)); }, {a}, opt);
  }
}

TEST_CASE("elementwise: complex add, sub, mul, div") {
  const Tensord ar = randn({3, 4}, 61), ai = randn({3, 4}, 62), br = randn({3, 4}, 63), bi = randn({3, 4}, 64);
  const Tensord rr = randn({1, 4}, 65), ri = randn({1, 4}, 66);
  auto bin = [](int op) {
    return [op](const std::vector<Tensord>& in) {
      const Tensorcd a = cplx(in[0], in[1]), b = cplx(in[2], in[3]);
      switch (op) {
        case 0:
          return split(a + b);
        case 1:
          return split(a - b);
        case 2:
          return split(a * b);
        default:
          return split(a / b);
      }
    };
  };
  const char* names[] = {"complex add", "complex sub", "complex mul", "complex div"};
  for (int op = 0; op < 4; ++op) {
    check_grad(names[op], kTol, bin(op), {ar, ai, br, bi});
    check_grad(std::string(names[op]) + " row broadcast", kTol, bin(op), {ar, ai, rr, ri});
  }
  // values
  const Tensorcd a = cplx(ar, ai), b = cplx(br, bi), p = a * b;
  for (int64_t i = 0; i < p.numel(); ++i) {
    const std::complex<double> e =
        std::complex<double>(ar.data()[i], ai.data()[i]) * std::complex<double>(br.data()[i], bi.data()[i]);
    CHECK(std::abs(p.data()[i] - e) < 1e-14);
  }
}

TEST_CASE("elementwise: float32 matches float64 within 1e-5") {
  const Tensord a = randn({8, 5}, 71), b = randn({8, 5}, 72), bp = randu({8, 5}, 73, 0.5, 2);
  auto f = [](const auto& x, const auto& y, const auto& yp) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    auto t = ag::tanh(x * y) + ag::sigmoid(x) / yp - ag::leaky_relu(x, T(0.02)) +
             ag::sqrt(yp) * ag::exp(ag::clamp(x, T(-1), T(1))) + ag::atan2(x, y) + ag::log(yp) - ag::pow(yp, T(1.5)) +
             ag::sin(x) * ag::cos(y) + ag::abs(y);
    return t;
  };
  const auto d = f(a, b, bp);
  const auto s = f(to_float(a), to_float(b), to_float(bp));
  CHECK(max_abs_diff(s, d) < 1e-5);
}

TEST_CASE("elementwise: atan2 gradient at subnormal-square and overflow-square magnitudes") {
  // y = x = a: d/dy = 1 / (2a), d/dx = -1 / (2a). x^2 + y^2 underflows (small a) or
  // overflows (large a) in the working precision; the scaled form must not.
  auto check = [](auto a) {
    using T = decltype(a);
    ag::Tensor<T> y = ag::Tensor<T>::full({1, 1}, a, true), x = ag::Tensor<T>::full({1, 1}, a, true);
    const ag::Tensor<T> v = ag::atan2(y, x);
    CHECK(double(v.item()) == doctest::Approx(M_PI / 4));
    sum(v).backward();
    const double want = 0.5 / double(a);
    CHECK(double(y.grad()[0]) == doctest::Approx(want).epsilon(1e-6));
    CHECK(double(x.grad()[0]) == doctest::Approx(-want).epsilon(1e-6));
  };
  for (float a : {1e-23f, 1e20f, 1e-30f, 3e37f}) {
    CAPTURE(a);
    check(a);
  }
  for (double a : {1e-170, 1e200, 1e-300, 1e300}) {
    CAPTURE(a);
    check(a);
  }
  // and a float64 gradient check at those scales (gradcheck's step is relative to them)
  for (double s : {1e-170, 1e200}) {
    CAPTURE(s);
    check_grad(
        "atan2 extreme", kTol, [](auto& in) { return ag::atan2(in[0], in[1]); },
        {randn({3, 3}, 61, s), randn({3, 3}, 62, s)});
  }
}

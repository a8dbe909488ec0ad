// Gradient checks of the row-wise vector ops, including zero vectors and scaled inputs.
#include "tests/support/ag_test_util.hpp"

#include <Eigen/Geometry>

using namespace agt;

namespace {
constexpr double kTol = 1e-6;  // smooth inputs (rows away from 0 unless stated)
}

TEST_CASE("vec3: dot_rows, cross3, norm_rows, normalize_rows on random inputs") {
  const Tensord a = randn({6, 3}, 1), b = randn({6, 3}, 2), w = randn({6, 5}, 3);
  check_grad("dot_rows", kTol, [](auto& in) { return ag::dot_rows(in[0], in[1]); }, {a, b});
  check_grad("dot_rows 5 cols", kTol, [](auto& in) { return ag::dot_rows(in[0], in[0]); }, {w});
  check_grad("cross3", kTol, [](auto& in) { return ag::cross3(in[0], in[1]); }, {a, b});
  check_grad("norm_rows", kTol, [](auto& in) { return ag::norm_rows(in[0]); }, {a});
  check_grad("normalize_rows", kTol, [](auto& in) { return ag::normalize_rows(in[0]); }, {a});
}

TEST_CASE("vec3: values") {
  const Tensord a = randn({4, 3}, 4), b = randn({4, 3}, 5);
  const Tensord c = ag::cross3(a, b), d = ag::dot_rows(a, b), n = ag::norm_rows(a), u = ag::normalize_rows(a);
  for (int64_t r = 0; r < 4; ++r) {
    const Eigen::Vector3d va = a.mat().row(r).transpose(), vb = b.mat().row(r).transpose();
    CHECK((c.mat().row(r).transpose() - va.cross(vb)).norm() < 1e-14);
    CHECK(d.at(r, 0) == doctest::Approx(va.dot(vb)));
    CHECK(n.at(r, 0) == doctest::Approx(va.norm()));
    CHECK((u.mat().row(r).transpose() - va.normalized()).norm() < 1e-14);
  }
}

TEST_CASE("vec3: zero vectors through norm_rows and normalize_rows") {
  Tensord x = Tensord::from({3, 3}, {0, 0, 0, 1, 2, 2, 0, 0, 0}, true);
  const Tensord n = ag::norm_rows(x);
  CHECK(n.at(0, 0) == 0.0);
  CHECK(n.at(1, 0) == 3.0);
  const Tensord u = ag::normalize_rows(x);
  CHECK(u.at(0, 0) == 0.0);
  CHECK(u.at(1, 2) == doctest::Approx(2.0 / 3.0));
  sum(n + sum_rows(u)).backward();
  CHECK(all_finite(x.grad()));
  // zero row: norm contributes 0 (subgradient), normalize contributes 1/eps per entry
  CHECK(x.grad()[0] == doctest::Approx(1e12).epsilon(1e-12));
  // gradient check of normalize at (and very near) a zero row: there y = x / eps is linear.
  // Step 1e-14 keeps x +- h inside the |x| < eps branch. Tolerance 1e-6 still holds.
  ag::GradCheckOptions opt;
  opt.step = 1e-14;
  check_grad(
      "normalize_rows zero row", kTol, [](auto& in) { return ag::normalize_rows(in[0], 1e-6); },
      {Tensord::zeros({2, 3})}, opt);
  check_grad("norm_rows of cross3", kTol, [](auto& in) { return ag::norm_rows(ag::cross3(in[0], in[1])); },
             {randn({4, 3}, 6), randn({4, 3}, 7)});
}

TEST_CASE("vec3: inputs scaled by 1e-3 and 1e3") {
  for (double s : {1e-3, 1e3}) {
    INFO("scale " << s);
    const ag::GradCheckOptions opt;  // gradcheck's step is relative to the input's size
    const Tensord a = randn({5, 3}, 8, s), b = randn({5, 3}, 9, s);
    check_grad(
        "dot scaled", kTol, [](auto& in) { return ag::dot_rows(in[0], in[1]); }, {a, b}, opt);
    check_grad(
        "cross scaled", kTol, [](auto& in) { return ag::cross3(in[0], in[1]); }, {a, b}, opt);
    check_grad(
        "norm scaled", kTol, [](auto& in) { return ag::norm_rows(in[0]); }, {a}, opt);
    check_grad(
        "normalize scaled", kTol, [](auto& in) { return ag::normalize_rows(in[0]); }, {a}, opt);
  }
  // mm vs m: normalize is scale invariant
  const Tensord a = randn({5, 3}, 10);
  const Tensord u1 = ag::normalize_rows(a), u2 = ag::normalize_rows(a * 1e-3);
  CHECK((u1.mat() - u2.mat()).cwiseAbs().maxCoeff() < 1e-14);
  // huge and tiny entries do not overflow / underflow the norm
  const Tensord big = Tensord::from({2, 3}, {3e200, 4e200, 0, 3e-200, 4e-200, 0});
  const Tensord nb = ag::norm_rows(big);
  CHECK(nb.at(0, 0) == doctest::Approx(5e200));
  CHECK(nb.at(1, 0) == doctest::Approx(5e-200));
}

TEST_CASE("vec3: cross3 needs 3 columns, shapes must agree") {
  CHECK_THROWS_WITH_AS(ag::cross3(randn({4, 2}, 1), randn({4, 2}, 2)), doctest::Contains("cross3"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::dot_rows(randn({4, 3}, 1), randn({5, 3}, 2)), doctest::Contains("[5 x 3]"), ag::Error);
}

TEST_CASE("vec3: float32 matches float64 within 1e-5") {
  const Tensord a = randn({20, 3}, 11), b = randn({20, 3}, 12);
  CHECK(max_abs_diff(ag::cross3(to_float(a), to_float(b)), ag::cross3(a, b)) < 1e-5);
  CHECK(max_abs_diff(ag::dot_rows(to_float(a), to_float(b)), ag::dot_rows(a, b)) < 1e-5);
  CHECK(max_abs_diff(ag::norm_rows(to_float(a)), ag::norm_rows(a)) < 1e-5);
  CHECK(max_abs_diff(ag::normalize_rows(to_float(a)), ag::normalize_rows(a)) < 1e-5);
}

TEST_CASE("vec3: norm_rows and normalize_rows at subnormal and near-overflow lengths") {
  // Rows (3a, 4a, 0): |x| = 5a, d|x|/dx = x/|x| = (0.6, 0.8, 0) and normalize = (0.6, 0.8, 0)
  // at every magnitude a, float32 and float64 (expected finite values, not only "no NaN").
  auto check = [](auto a, bool norm_overflows) {
    using T = decltype(a);
    ag::Tensor<T> x = ag::Tensor<T>::from({1, 3}, {T(3) * a, T(4) * a, T(0)}, true);
    const ag::Tensor<T> n = ag::norm_rows(x);
    if (norm_overflows)
      CHECK(std::isinf(n.item()));  // 5a itself exceeds the largest float
    else
      CHECK(double(n.item()) == doctest::Approx(5 * double(a)).epsilon(1e-6));
    sum(n).backward();
    CHECK(double(x.grad()[0]) == doctest::Approx(0.6).epsilon(1e-6));
    CHECK(double(x.grad()[1]) == doctest::Approx(0.8).epsilon(1e-6));
    CHECK(x.grad()[2] == T(0));
    // normalize with the smallest positive eps: the exact unit vector
    const ag::Tensor<T> u = ag::normalize_rows(x.detach(), std::numeric_limits<T>::denorm_min());
    CHECK(double(u.at(0, 0)) == doctest::Approx(0.6).epsilon(1e-6));
    CHECK(double(u.at(0, 1)) == doctest::Approx(0.8).epsilon(1e-6));
  };
  for (float a : {1e-40f, 1e-20f, 1e20f, 5e37f}) {
    CAPTURE(a);
    check(a, false);
  }
  check(7.5e37f, true);  // 4a is finite, 5a is not
  for (double a : {6e-311, 1e-160, 1e160, 3e307}) {
    CAPTURE(a);
    check(a, false);
  }
  check(4e307, true);
  // normalize's gradient (g - y (y.g)) / |x| near overflow: ~1/|x|, finite and right
  ag::Tensord x = ag::Tensord::from({1, 3}, {3e307, 4e307, 0}, true);
  sum(ag::normalize_rows(x) * ag::Tensord::from({1, 3}, {0.0, 0.0, 1.0})).backward();
  CHECK(x.grad()[2] == doctest::Approx(1.0 / 5e307));
  CHECK(x.grad()[0] == 0.0);
}

TEST_CASE("vec3: gradient checks at 1e-150 and 1e150 and eps must be positive") {
  for (double s : {1e-150, 1e150}) {
    CAPTURE(s);
    const Tensord a = randn({5, 3}, 21, s);
    check_grad("norm extreme", kTol, [](auto& in) { return ag::norm_rows(in[0]); }, {a});
    check_grad("normalize extreme", kTol, [](auto& in) { return ag::normalize_rows(in[0], 1e-300); }, {a});
  }
  const Tensord a = randn({2, 3}, 22);
  CHECK_THROWS_WITH_AS(ag::normalize_rows(a, 0.0), doctest::Contains("eps"), ag::Error);
  CHECK_THROWS_AS(ag::normalize_rows(a, -1.0), ag::Error);
}

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
        "channel_norm scaled", kTol, [](auto& in) { return ag::channel_norm(in[0]); }, {randn({7, 4}, 2, s)});
    check_grad(
        "layer_norm scaled", kTol, [](auto& in) { return ag::layer_norm(in[0]); }, {randn({7, 4}, 3, s)});
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

TEST_CASE("norm: rows near the float range's ends give the exact O(1) result") {
  // float32 rows of size 1e20 (squares overflow) and 1e-30 (squares underflow), float64 rows
  // of size 1e160 and 1e-200: compared with the float64 formula on the unscaled pattern.
  const Tensord p = randn({3, 5}, 30);
  auto reference = [&p](double s, double eps, bool per_row) {
    Eigen::MatrixXd m = p.mat(), out(m.rows(), m.cols());
    for (int k = 0; k < (per_row ? m.rows() : m.cols()); ++k) {
      Eigen::VectorXd v = per_row ? Eigen::VectorXd(m.row(k).transpose()) : Eigen::VectorXd(m.col(k));
      const double mu = v.mean(), var = (v.array() - mu).square().mean();
      // (s x - s mu) / sqrt(s^2 var + eps) = (x - mu) / sqrt(var + eps / s^2)
      const Eigen::VectorXd o = (v.array() - mu) / std::sqrt(var + eps / s / s);
      if (per_row)
        out.row(k) = o.transpose();
      else
        out.col(k) = o;
    }
    return out;
  };
  auto check = [&](auto s, double tol) {
    using T = decltype(s);
    std::vector<T> v;
    for (double e : p.values()) v.push_back(static_cast<T>(e * double(s)));
    const ag::Tensor<T> x = ag::Tensor<T>::from(p.shape(), v);
    for (bool per_row : {true, false}) {
      CAPTURE(per_row);
      const ag::Tensor<T> y = per_row ? ag::layer_norm(x) : ag::channel_norm(x);
      const Eigen::MatrixXd want = reference(double(s), 1e-5, per_row);
      double err = 0;
      for (int64_t i = 0; i < y.numel(); ++i)
        err = std::max(err, std::abs(double(y.data()[i]) - want(i / p.cols(), i % p.cols())));
      CHECK(err < tol);
    }
  };
  for (float s : {1e20f, 1e35f, 1e-30f}) {
    CAPTURE(s);
    check(s, 1e-5);
  }
  for (double s : {1e160, 1e300, 1e-200}) {
    CAPTURE(s);
    check(s, 1e-12);
  }
  // float64 gradient checks there (gradcheck's step and floor are relative to the inputs)
  for (double s : {1e160, 1e-200}) {
    CAPTURE(s);
    check_grad("layer_norm extreme", kTol, [](auto& in) { return ag::layer_norm(in[0]); }, {randn({4, 5}, 31, s)});
    check_grad("channel_norm extreme", kTol, [](auto& in) { return ag::channel_norm(in[0]); }, {randn({5, 4}, 32, s)});
  }
  // float32 gradient at 1e20 agrees with float64's
  const Tensord xd = (randn({3, 5}, 33) * 1e20).detach().set_requires_grad(true);
  Tensorf xf = to_float(xd).set_requires_grad(true);
  const Tensord w = randn({3, 5}, 34);
  sum(ag::layer_norm(xd) * w).backward();
  sum(ag::layer_norm(xf) * to_float(w)).backward();
  for (size_t i = 0; i < xd.grad().size(); ++i)
    CHECK(double(xf.grad()[i]) == doctest::Approx(xd.grad()[i]).epsilon(1e-4));
}

TEST_CASE("norm: eps must be finite and positive") {
  const Tensord x = randn({3, 4}, 35);
  CHECK_THROWS_WITH_AS(ag::layer_norm(x, 0.0), doctest::Contains("layer_norm: eps"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::channel_norm(x, -1e-5), doctest::Contains("channel_norm: eps"), ag::Error);
  CHECK_THROWS_AS(ag::layer_norm(x, std::nan("")), ag::Error);
}

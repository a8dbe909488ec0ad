// Gradient checks and reference comparisons of grouped_linear (real and complex).
#include "ag_test_util.hpp"

using namespace agt;
using ag::Tensorcd;

namespace {
constexpr double kTol = 1e-6;  // bilinear op

// Per-row reference: y[n] = W[g] x[n] + b[g].
Eigen::MatrixXcd reference(const Tensorcd& x, const Tensorcd& w, const Tensorcd& b, const ag::Index& group,
                           int64_t out) {
  const int64_t N = x.rows(), in = x.cols();
  Eigen::MatrixXcd y(N, out);
  for (int64_t n = 0; n < N; ++n) {
    const auto W = ag::ConstMatMap<std::complex<double>>(w.data() + group[n] * out * in, out, in);
    y.row(n) = (W * x.mat().row(n).transpose()).transpose() + b.mat().row(group[n]);
  }
  return y;
}
}  // namespace

TEST_CASE("grouped_linear: real gradient, sorted and unsorted groups, with and without bias") {
  const int64_t G = 4, in = 3, out = 2, N = 11;
  const Tensord x = randn({N, in}, 1), w = randn({G, out * in}, 2), b = randn({G, out}, 3);
  ag::Index unsorted = rand_index(N, G - 1, 4);  // group G-1 stays empty
  ag::Index sorted = unsorted;
  std::sort(sorted.begin(), sorted.end());
  for (const auto& [name, grp] : {std::pair{"unsorted", unsorted}, std::pair{"sorted", sorted}}) {
    const ag::Index g = grp;
    check_grad(std::string("grouped_linear ") + name, kTol,
               [g](auto& in) { return ag::grouped_linear(in[0], in[1], in[2], g, 2); }, {x, w, b});
    check_grad(std::string("grouped_linear no bias ") + name, kTol,
               [g](auto& in) { return ag::grouped_linear(in[0], in[1], Tensord(), g, 2); }, {x, w});
  }
  // value against a per-row loop
  const Tensord y = ag::grouped_linear(x, w, b, unsorted, out);
  double err = 0;
  for (int64_t n = 0; n < N; ++n) {
    const auto W = ag::ConstMatMap<double>(w.data() + unsorted[n] * out * in, out, in);
    const Eigen::VectorXd e = W * x.mat().row(n).transpose() + b.mat().row(unsorted[n]).transpose();
    err = std::max(err, (y.mat().row(n).transpose() - e).cwiseAbs().maxCoeff());
  }
  CHECK(err < 1e-14);
}

TEST_CASE("grouped_linear: complex gradient and value") {
  const int64_t G = 3, in = 3, out = 2, N = 9;
  const Tensord xr = randn({N, in}, 5), xi = randn({N, in}, 6), wr = randn({G, out * in}, 7),
                wi = randn({G, out * in}, 8), br = randn({G, out}, 9), bi = randn({G, out}, 10);
  const ag::Index g = rand_index(N, G, 11);
  check_grad("complex grouped_linear", kTol,
             [g](auto& in) {
               return split(ag::grouped_linear(cplx(in[0], in[1]), cplx(in[2], in[3]), cplx(in[4], in[5]), g, 2));
             },
             {xr, xi, wr, wi, br, bi});
  const Tensorcd x = cplx(xr, xi), w = cplx(wr, wi), b = cplx(br, bi);
  const Tensorcd y = ag::grouped_linear(x, w, b, g, out);
  CHECK((y.mat() - reference(x, w, b, g, out)).cwiseAbs().maxCoeff() < 1e-14);
}

TEST_CASE("grouped_linear: large parallel case matches the per-row reference") {
  const int64_t G = 300, in = 16, out = 8, N = 5000;
  const Tensorcd x = cplx(randn({N, in}, 12), randn({N, in}, 13));
  const Tensorcd w = cplx(randn({G, out * in}, 14), randn({G, out * in}, 15));
  const Tensorcd b = cplx(randn({G, out}, 16), randn({G, out}, 17));
  const ag::Index g = rand_index(N, G, 18);
  const Tensorcd y = ag::grouped_linear(x, w, b, g, out);
  CHECK((y.mat() - reference(x, w, b, g, out)).cwiseAbs().maxCoeff() < 1e-12);
  // float32 complex agrees with float64
  auto tf = [](const Tensorcd& t) {
    std::vector<std::complex<float>> v(t.values().begin(), t.values().end());
    return ag::Tensorcf::from(t.shape(), v);
  };
  const ag::Tensorcf yf = ag::grouped_linear(tf(x), tf(w), tf(b), g, out);
  double err = 0;
  for (int64_t i = 0; i < y.numel(); ++i)
    err = std::max(err, std::abs(std::complex<double>(yf.data()[i]) - y.data()[i]) / (1 + std::abs(y.data()[i])));
  CHECK(err < 1e-5);
}

TEST_CASE("grouped_linear: errors name the op and the shapes") {
  const Tensord x = randn({4, 3}, 1), w = randn({2, 6}, 2);
  CHECK_THROWS_WITH_AS(ag::grouped_linear(x, w, Tensord(), {0, 1, 0, 2}, 2), doctest::Contains("grouped_linear"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::grouped_linear(x, w, Tensord(), {0, 1, 0}, 2), doctest::Contains("[4 x 3]"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::grouped_linear(x, w, Tensord(), {0, 1, 0, 1}, 3), doctest::Contains("[2 x 6]"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::grouped_linear(x, w, randn({2, 3}, 3), {0, 1, 0, 1}, 2), doctest::Contains("[2 x 3]"), ag::Error);
}

// Gradient checks of matmul, linear and transpose (real and complex).
#include "tests/support/ag_test_util.hpp"

#include "autograd/gemm_blocks.hpp"

using namespace agt;
using ag::Tensorcd;

namespace {
constexpr double kTol = 1e-6;  // smooth (bilinear) ops
}

TEST_CASE("matmul: gradient and value") {
  const Tensord a = randn({5, 3}, 1), b = randn({3, 4}, 2);
  check_grad("matmul", kTol, [](auto& in) { return ag::matmul(in[0], in[1]); }, {a, b});
  const Tensord c = ag::matmul(a, b);
  const Eigen::MatrixXd e = a.mat() * b.mat();
  CHECK((c.mat() - e).cwiseAbs().maxCoeff() < 1e-14);
}

TEST_CASE("matmul: shape mismatch names the op and both shapes") {
  const Tensord a = randn({5, 3}, 1), b = randn({4, 4}, 2);
  CHECK_THROWS_WITH_AS(ag::matmul(a, b), doctest::Contains("matmul"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::matmul(a, b), doctest::Contains("[5 x 3]"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::matmul(a, b), doctest::Contains("[4 x 4]"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::linear(a, b, Tensord()), doctest::Contains("linear"), ag::Error);
}

TEST_CASE("linear: with and without bias, scaled inputs") {
  const Tensord x = randn({6, 4}, 3), w = randn({3, 4}, 4), b = randn({1, 3}, 5);
  check_grad("linear+bias", kTol, [](auto& in) { return ag::linear(in[0], in[1], in[2]); }, {x, w, b});
  check_grad("linear", kTol, [](auto& in) { return ag::linear(in[0], in[1], Tensord()); }, {x, w});
  for (double s : {1e-3, 1e3}) {
    INFO("scale " << s);
    check_grad(
        "linear scaled", kTol, [](auto& in) { return ag::linear(in[0], in[1], in[2]); },
        {randn({6, 4}, 6, s), randn({3, 4}, 7, s), randn({1, 3}, 8, s)}, step_for_multilinear());
  }
  const Tensord y = ag::linear(x, w, b);
  const Eigen::MatrixXd e = (x.mat() * w.mat().transpose()).rowwise() + b.mat().row(0);
  CHECK((y.mat() - e).cwiseAbs().maxCoeff() < 1e-14);
}

TEST_CASE("transpose: gradient and value") {
  const Tensord a = randn({5, 3}, 9);
  check_grad("transpose", kTol, [](auto& in) { return ag::transpose(in[0]); }, {a});
  const Tensord t = ag::transpose(a);
  CHECK(t.shape() == ag::Shape{3, 5});
  CHECK(t.at(2, 4) == a.at(4, 2));
}

TEST_CASE("matmul, linear, transpose: complex") {
  const Tensord ar = randn({4, 3}, 11), ai = randn({4, 3}, 12), br = randn({3, 5}, 13), bi = randn({3, 5}, 14),
                cr = randn({1, 5}, 15), ci = randn({1, 5}, 16);
  check_grad("complex matmul", kTol, [](auto& in) { return split(ag::matmul(cplx(in[0], in[1]), cplx(in[2], in[3]))); },
             {ar, ai, br, bi});
  // linear: x [4 x 3], weight [5 x 3] = transpose of b
  check_grad("complex linear", kTol,
             [](auto& in) {
               return split(ag::linear(cplx(in[0], in[1]), ag::transpose(cplx(in[2], in[3])), cplx(in[4], in[5])));
             },
             {ar, ai, br, bi, cr, ci});
  check_grad("complex transpose", kTol, [](auto& in) { return split(ag::transpose(cplx(in[0], in[1]))); }, {ar, ai});
}

TEST_CASE("matmul, linear: float32 matches float64 within 1e-5") {
  const Tensord x = randn({7, 6}, 21, 0.3), w = randn({5, 6}, 22, 0.3), b = randn({1, 5}, 23);
  const auto d = ag::linear(x, w, b);
  const auto s = ag::linear(to_float(x), to_float(w), to_float(b));
  CHECK(max_abs_diff(s, d) < 1e-5);
  CHECK(max_abs_diff(ag::matmul(to_float(x), ag::transpose(to_float(w))), ag::matmul(x, ag::transpose(w))) < 1e-5);
}

TEST_CASE("linear_leaky_relu: gradient, and equal to leaky_relu(linear) bit for bit") {
  const Tensord x = randn({7, 5}, 11), w = randn({4, 5}, 12), b = randn({1, 4}, 13);
  const Tensord pre = ag::linear(x, w, b);
  REQUIRE(pre.mat().cwiseAbs().minCoeff() > 1e-3);  // finite differences stay off the kink
  check_grad("linear_leaky_relu+bias", kTol, [](auto& in) { return ag::linear_leaky_relu(in[0], in[1], in[2], 0.02); },
             {x, w, b});
  check_grad("linear_leaky_relu", kTol, [](auto& in) { return ag::linear_leaky_relu(in[0], in[1], Tensord(), 0.3); },
             {x, w});
  // float32, large enough for the parallel path: same values and gradients as the two ops
  const Tensorf xf = to_float(randn({3000, 64}, 14)), wf = to_float(randn({48, 64}, 15, 0.2)),
                bf = to_float(randn({1, 48}, 16)), cf = to_float(randn({3000, 48}, 17));
  auto run = [&](bool fused) {
    Tensorf xl = xf.detach().set_requires_grad(true), wl = wf.detach().set_requires_grad(true),
            bl = bf.detach().set_requires_grad(true);
    const Tensorf y = fused ? ag::linear_leaky_relu(xl, wl, bl, 0.02f) : ag::leaky_relu(ag::linear(xl, wl, bl), 0.02f);
    ag::sum(ag::mul(y, cf)).backward();
    return std::vector<ag::Storage<float>>{y.values(), xl.grad(), wl.grad(), bl.grad()};
  };
  const auto f = run(true), u = run(false);
  for (size_t k = 0; k < f.size(); ++k) CHECK(f[k] == u[k]);
  CHECK_THROWS_WITH_AS(ag::linear_leaky_relu(x, w, b, 0.0), doctest::Contains("linear_leaky_relu"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::linear_leaky_relu(x, randn({4, 3}, 18), b, 0.1), doctest::Contains("[7 x 5]"), ag::Error);
}

// Products big enough to be cut into tiles (autograd/gemm_blocks.hpp) give one whole Eigen
// product's values and gradients, also where the tiles run on several threads.
TEST_CASE("matmul and linear: tiled products equal one whole product") {
  const int64_t M = 300, K = 1000, N = 700;
  const ag::gemm::Tiling t = ag::gemm::tiling(M, N, K);
  REQUIRE(t.row_tiles * t.col_tiles > 2);  // the shape really is split, in both directions
  REQUIRE(t.col_tiles > 1);
  Tensord a = randn({M, K}, 11), b = randn({K, N}, 12), w = randn({N, K}, 13), r = randn({M, N}, 14);
  a.set_requires_grad(true), b.set_requires_grad(true), w.set_requires_grad(true);
  const Eigen::MatrixXd A = a.mat(), B = b.mat(), W = w.mat(), R = r.mat();
  auto err = [](const Eigen::MatrixXd& x, const Eigen::MatrixXd& ref) {
    return (x - ref).cwiseAbs().maxCoeff() / ref.cwiseAbs().maxCoeff();
  };
  const Tensord c = ag::matmul(a, b);
  CHECK(err(c.mat(), A * B) < 1e-13);
  ag::sum(ag::mul(c, r)).backward();  // dA = R B^T, dB = A^T R
  CHECK(err(a.grad_mat(), R * B.transpose()) < 1e-13);
  CHECK(err(b.grad_mat(), A.transpose() * R) < 1e-13);
  a.zero_grad();
  const Tensord y = ag::linear(a, w, Tensord());
  CHECK(err(y.mat(), A * W.transpose()) < 1e-13);
  ag::sum(ag::mul(y, r)).backward();  // dX = R W, dW = R^T X
  CHECK(err(a.grad_mat(), R * W) < 1e-13);
  CHECK(err(w.grad_mat(), R.transpose() * A) < 1e-13);
}

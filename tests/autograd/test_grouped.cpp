// Gradient checks and reference comparisons of grouped_linear (real and complex).
#include "tests/support/ag_test_util.hpp"

#include <omp.h>

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

// Sorted complex groups run the SIMD kernel (grouped_kernel.hpp): widths with partial
// packets, groups longer than one packet of rows, an empty group.
TEST_CASE("grouped_linear: complex kernel (sorted groups) gradient") {
  for (const auto& [in, out] : {std::pair<int64_t, int64_t>{3, 2}, {9, 5}, {5, 11}}) {
    const int64_t G = 4, N = 23;
    const Tensord xr = randn({N, in}, 21), xi = randn({N, in}, 22), wr = randn({G, out * in}, 23),
                  wi = randn({G, out * in}, 24), br = randn({G, out}, 25), bi = randn({G, out}, 26);
    ag::Index g = rand_index(N, G - 1, 27);  // group G-1 empty
    g[0] = 0;
    for (int64_t k = 1; k <= 12; ++k) g[k] = 1;  // one long group
    std::sort(g.begin(), g.end());
    const int64_t o = out;
    check_grad("complex grouped_linear kernel " + std::to_string(in) + "x" + std::to_string(out), kTol,
               [g, o](auto& v) {
                 return split(ag::grouped_linear(cplx(v[0], v[1]), cplx(v[2], v[3]), cplx(v[4], v[5]), g, o));
               },
               {xr, xi, wr, wi, br, bi});
    check_grad(
        "complex grouped_linear kernel no bias", kTol,
        [g, o](auto& v) { return split(ag::grouped_linear(cplx(v[0], v[1]), cplx(v[2], v[3]), ag::Tensorcd(), g, o)); },
        {xr, xi, wr, wi});
  }
}

namespace {
// Value and all three gradients of sum(Re(c * y)) for the field's shape (64 x 64 complex,
// ~6.5 rows per group), with a given thread count.
struct GroupedRun {
  std::vector<std::complex<double>> y, dx, dw, db;
};
GroupedRun run_grouped(const Tensorcd& x0, const Tensorcd& w0, const Tensorcd& b0, const Tensorcd& c,
                       const ag::Index& g, int64_t out, int threads) {
  omp_set_num_threads(threads);
  Tensorcd x = x0.detach().set_requires_grad(true), w = w0.detach().set_requires_grad(true),
           b = b0.detach().set_requires_grad(true);
  const Tensorcd y = ag::grouped_linear(x, w, b, g, out);
  ag::sum(ag::real(ag::mul(y, c))).backward();
  omp_set_num_threads(omp_get_num_procs());
  return {ag::to_vector(y.values()), ag::to_vector(x.grad()), ag::to_vector(w.grad()), ag::to_vector(b.grad())};
}
}  // namespace

TEST_CASE("grouped_linear: complex kernel at the field's size matches a per-row reference, any thread count") {
  const int64_t G = 230, in = 64, out = 64, N = 1500;
  const Tensorcd x = cplx(randn({N, in}, 31), randn({N, in}, 32));
  const Tensorcd w = cplx(randn({G, out * in}, 33, 0.1), randn({G, out * in}, 34, 0.1));
  const Tensorcd b = cplx(randn({G, out}, 35), randn({G, out}, 36));
  const Tensorcd c = cplx(randn({N, out}, 37), randn({N, out}, 38));
  ag::Index g = rand_index(N, G, 39);
  std::sort(g.begin(), g.end());
  const GroupedRun r1 = run_grouped(x, w, b, c, g, out, 1), r2 = run_grouped(x, w, b, c, g, out, 2);
  CHECK(r1.y == r2.y);  // bit for bit: each group is computed by one thread
  CHECK(r1.dx == r2.dx);
  CHECK(r1.dw == r2.dw);
  CHECK(r1.db == r2.db);
  // Reference: y = W x + b per row; the loss is sum Re(c y), so grad y = conj(c) and
  // dx = W^H conj(c), dW += conj(c) x^H (PyTorch's convention, see tensor.hpp).
  const Eigen::MatrixXcd yref = reference(x, w, b, g, out);
  double ey = 0, ex = 0, ew = 0, eb = 0;
  Eigen::MatrixXcd dw = Eigen::MatrixXcd::Zero(G, out * in), db = Eigen::MatrixXcd::Zero(G, out);
  for (int64_t n = 0; n < N; ++n) {
    const auto W = ag::ConstMatMap<std::complex<double>>(w.data() + g[n] * out * in, out, in);
    const Eigen::VectorXcd gy = c.mat().row(n).conjugate().transpose();
    const Eigen::VectorXcd xn = x.mat().row(n).transpose();
    const Eigen::VectorXcd dxn = W.adjoint() * gy;
    for (int64_t i = 0; i < in; ++i) ex = std::max(ex, std::abs(r1.dx[n * in + i] - dxn[i]));
    for (int64_t o = 0; o < out; ++o) {
      ey = std::max(ey, std::abs(r1.y[n * out + o] - yref(n, o)));
      db(g[n], o) += gy[o];
      for (int64_t i = 0; i < in; ++i) dw(g[n], o * in + i) += gy[o] * std::conj(xn[i]);
    }
  }
  for (int64_t k = 0; k < G; ++k) {
    for (int64_t j = 0; j < out * in; ++j) ew = std::max(ew, std::abs(r1.dw[k * out * in + j] - dw(k, j)));
    for (int64_t o = 0; o < out; ++o) eb = std::max(eb, std::abs(r1.db[k * out + o] - db(k, o)));
  }
  CHECK(ey < 1e-12);
  CHECK(ex < 1e-12);
  CHECK(ew < 1e-12);
  CHECK(eb < 1e-12);
}

TEST_CASE("grouped_linear: errors name the op and the shapes") {
  const Tensord x = randn({4, 3}, 1), w = randn({2, 6}, 2);
  CHECK_THROWS_WITH_AS(ag::grouped_linear(x, w, Tensord(), {0, 1, 0, 2}, 2), doctest::Contains("grouped_linear"),
                       ag::Error);
  CHECK_THROWS_WITH_AS(ag::grouped_linear(x, w, Tensord(), {0, 1, 0}, 2), doctest::Contains("[4 x 3]"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::grouped_linear(x, w, Tensord(), {0, 1, 0, 1}, 3), doctest::Contains("[2 x 6]"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::grouped_linear(x, w, randn({2, 3}, 3), {0, 1, 0, 1}, 2), doctest::Contains("[2 x 3]"),
                       ag::Error);
}

TEST_CASE("grouped_linear_planes: gradient, and equal to grouped_linear on sliced planes") {
  const int64_t G = 4, in = 5, out = 3, N = 17, P = 2 + in * out + out + 4;  // weights at 2, bias after
  const int64_t wb = 2, bb = 2 + in * out;
  const Tensord xr = randn({N, in}, 51), xi = randn({N, in}, 52), re = randn({G, P}, 53), im = randn({G, P}, 54);
  ag::Index g = rand_index(N, G - 1, 55);
  std::sort(g.begin(), g.end());
  check_grad("grouped_linear_planes", kTol,
             [g](auto& v) { return split(ag::grouped_linear_planes(cplx(v[0], v[1]), v[2], v[3], 2, 2 + 15, g, 3)); },
             {xr, xi, re, im});
  check_grad("grouped_linear_planes no bias", kTol,
             [g](auto& v) { return split(ag::grouped_linear_planes(cplx(v[0], v[1]), v[2], v[3], 2, -1, g, 3)); },
             {xr, xi, re, im});
  // Same value as the sliced and interleaved weights through grouped_linear (general path).
  const Tensorcd x = cplx(xr, xi);
  const Tensorcd w = cplx(ag::slice_cols(re, wb, wb + in * out), ag::slice_cols(im, wb, wb + in * out));
  const Tensorcd b = cplx(ag::slice_cols(re, bb, bb + out), ag::slice_cols(im, bb, bb + out));
  const Tensorcd y = ag::grouped_linear_planes(x, re, im, wb, bb, g, out);
  CHECK((y.mat() - reference(x, w, b, g, out)).cwiseAbs().maxCoeff() < 1e-13);
  ag::Index unsorted = g;
  std::swap(unsorted[0], unsorted[N - 1]);
  CHECK_THROWS_WITH_AS(ag::grouped_linear_planes(x, re, im, wb, bb, unsorted, out), doctest::Contains("sorted"),
                       ag::Error);
  CHECK_THROWS_WITH_AS(ag::grouped_linear_planes(x, re, im, P - 3, bb, g, out), doctest::Contains("do not fit"),
                       ag::Error);
}

namespace {
// grouped_linear_planes (planes kernels, grouped_planes_kernel.hpp) against grouped_linear on
// the same weights sliced and interleaved (the rows-in-lanes kernels), value and all
// gradients of sum(Re(c * y)), in scalar type R. Returns the largest difference relative to
// the largest magnitude of each compared quantity.
template <class R> double planes_vs_interleaved(int64_t in, int64_t out, const ag::Index& g, int64_t G) {
  using C = std::complex<R>;
  auto real_t = [](const Tensord& t) {
    if constexpr (std::is_same_v<R, double>)
      return t;
    else
      return to_float(t);
  };
  const int64_t N = static_cast<int64_t>(g.size()), wb = 1, bb = 1 + in * out, P = bb + out + 2;  // unaligned start
  const auto x0 = ag::complex_from(real_t(randn({N, in}, 61)), real_t(randn({N, in}, 62)));
  const auto re0 = real_t(randn({G, P}, 63, 0.2)), im0 = real_t(randn({G, P}, 64, 0.2));
  const auto c = ag::complex_from(real_t(randn({N, out}, 65)), real_t(randn({N, out}, 66)));
  auto fresh = [](const auto& t) { return t.detach().set_requires_grad(true); };
  auto xa = fresh(x0), ra = fresh(re0), ia = fresh(im0);
  const ag::Tensor<C> ya = ag::grouped_linear_planes(xa, ra, ia, wb, bb, g, out);
  ag::sum(ag::real(ag::mul(ya, c))).backward();
  auto xb = fresh(x0), rb = fresh(re0), ib = fresh(im0);
  const ag::Tensor<C> yb =
      ag::grouped_linear(xb, ag::complex_from(ag::slice_cols(rb, wb, bb), ag::slice_cols(ib, wb, bb)),
                         ag::complex_from(ag::slice_cols(rb, bb, bb + out), ag::slice_cols(ib, bb, bb + out)), g, out);
  ag::sum(ag::real(ag::mul(yb, c))).backward();
  double worst = 0;
  auto compare = [&](const auto& a, const auto& b) {
    REQUIRE(a.size() == b.size());
    double d = 0, m = 0;
    for (size_t k = 0; k < a.size(); ++k) {
      const double e = std::abs(a[k] - b[k]);
      d = std::isnan(e) ? HUGE_VAL : std::max(d, e);  // std::max would drop a NaN
      m = std::max(m, double(std::abs(b[k])));
    }
    worst = std::max(worst, d / m);
  };
  compare(ya.values(), yb.values());
  compare(xa.grad(), xb.grad());
  compare(ra.grad(), rb.grad());
  compare(ia.grad(), ib.grad());
  return worst;
}
}  // namespace

TEST_CASE("grouped_linear_planes: the planes kernels match the interleaved ones at the field's size and ragged sizes") {
  // Group sizes 0..13 (empty groups, single rows, more rows than one register block of 6).
  const int64_t G = 40;
  ag::Index g;
  for (int64_t k = 0; k < G; ++k)
    for (int64_t r = 0; r < (k * 7) % 14; ++r) g.push_back(k);
  for (const auto& [in, out] : {std::pair<int64_t, int64_t>{64, 64}, {64, 3}, {40, 19}, {7, 33}, {16, 8}}) {
    CAPTURE(in);
    CAPTURE(out);
    CHECK(planes_vs_interleaved<double>(in, out, g, G) < 1e-13);
    CHECK(planes_vs_interleaved<float>(in, out, g, G) < 1e-5);  // float rounding, summed in another order
  }
}

// GDSR's field: several layers read one pair of planes, each its own columns, and a real layer
// reads another block through slice_cols. The first backward into fresh planes writes each
// layer's columns (claim_grad_columns); slice_cols adds; columns nobody reads come out 0; a
// second backward adds to all of it.
TEST_CASE("grouped_linear_planes: layers sharing planes write their columns, then add on a second backward") {
  const int64_t G = 5, f = 4, P = f + 2 * (f * f + f) + 2;  // [real block f][layer 1][layer 2][unused 2]
  const int64_t w1 = f, b1 = w1 + f * f, w2 = b1 + f, b2 = w2 + f * f;
  ag::Index g{0, 0, 1, 3, 3, 3, 4};  // group 2 has no rows
  const int64_t N = static_cast<int64_t>(g.size());
  auto f_of = [&](const std::vector<Tensord>& v) {
    // As in the field, the real block feeds the first complex layer, so its backward runs last.
    const Tensord block = ag::index_select_rows(ag::slice_cols(v[1], 0, f), g);  // re only
    const Tensorcd h1 = ag::grouped_linear_planes(cplx(ag::mul(v[0], block), v[3]), v[1], v[2], w1, b1, g, f);
    const Tensorcd h2 = ag::grouped_linear_planes(h1, v[1], v[2], w2, -1, g, f);
    return ag::sum(ag::add(ag::real(h2), ag::mul_scalar(ag::imag(h2), 0.3)));
  };
  const Tensord x = randn({N, f}, 71), re = randn({G, P}, 72), im = randn({G, P}, 73), s = randn({N, f}, 74);
  // Against finite differences, and the planes' gradient against the same model built on copies
  // that an earlier backward has already given a gradient (every op adds there).
  check_grad("planes shared by two layers and a slice", kTol, [&](auto& v) { return f_of(v); }, {x, re, im, s});
  auto leaf = [](const Tensord& t) { return t.detach().set_requires_grad(true); };
  std::vector<Tensord> a{leaf(x), leaf(re), leaf(im), leaf(s)};
  f_of(a).backward();
  const ag::Storage<double> re1 = a[1].grad(), im1 = a[2].grad();
  for (const ag::Storage<double>* d : {&re1, &im1}) {
    CHECK(all_finite(*d));
    for (int64_t r = 0; r < G; ++r)
      for (int64_t c = P - 2; c < P; ++c) CHECK((*d)[r * P + c] == 0.0);  // unused columns
    for (int64_t c = w1; c < b2; ++c) CHECK((*d)[2 * P + c] == 0.0);      // the empty group
  }
  for (int64_t c = 0; c < f; ++c) CHECK(im1[c] == 0.0);  // the real block's im part is unused
  // Second pass: the planes hold a gradient now, so both layers add.
  f_of(a).backward();
  for (size_t k = 0; k < re1.size(); ++k) {
    CHECK(a[1].grad()[k] == doctest::Approx(2 * re1[k]).epsilon(1e-12));
    CHECK(a[2].grad()[k] == doctest::Approx(2 * im1[k]).epsilon(1e-12));
  }
}

// Gradient checks of gather / scatter / interpolate.
#include "tests/support/ag_test_util.hpp"

#include <omp.h>

using namespace agt;

namespace {
constexpr double kTol = 1e-6;  // linear (bilinear for interpolate) ops
}

TEST_CASE("index: index_select_rows with repeated indices") {
  const Tensord x = randn({5, 3}, 1);
  const ag::Index idx{4, 0, 0, 2, 4, 4, 1};
  check_grad("index_select_rows", kTol, [idx](auto& in) { return ag::index_select_rows(in[0], idx); }, {x});
  const Tensord y = ag::index_select_rows(x, idx);
  CHECK(y.shape() == ag::Shape{7, 3});
  CHECK(y.at(5, 2) == x.at(4, 2));
  // gradient of sum(gather) counts the uses of each row
  Tensord xl = x.detach().set_requires_grad(true);
  sum(ag::index_select_rows(xl, idx)).backward();
  CHECK(xl.grad()[4 * 3] == 3.0);
  CHECK(xl.grad()[3 * 3] == 0.0);
}

TEST_CASE("index: scatter_add_rows and scatter_mean_rows") {
  const Tensord x = randn({8, 3}, 2);
  const ag::Index idx{0, 2, 2, 5, 0, 2, 1, 5};  // rows 3, 4 get nothing
  check_grad("scatter_add_rows", kTol, [idx](auto& in) { return ag::scatter_add_rows(in[0], idx, 6); }, {x});
  check_grad("scatter_mean_rows", kTol, [idx](auto& in) { return ag::scatter_mean_rows(in[0], idx, 6); }, {x});
  const Tensord s = ag::scatter_add_rows(x, idx, 6), m = ag::scatter_mean_rows(x, idx, 6);
  CHECK(s.shape() == ag::Shape{6, 3});
  CHECK(s.at(2, 1) == doctest::Approx(x.at(1, 1) + x.at(2, 1) + x.at(5, 1)));
  CHECK(m.at(2, 1) == doctest::Approx((x.at(1, 1) + x.at(2, 1) + x.at(5, 1)) / 3));
  CHECK(s.at(3, 0) == 0.0);
  CHECK(m.at(4, 2) == 0.0);
}

TEST_CASE("index: interpolate_rows w.r.t. x and weight") {
  const Tensord x = randn({6, 4}, 3);
  const Tensord w = randu({5, 3}, 4, 0.0, 1.0);
  const ag::Index idx = rand_index(5 * 3, 6, 5);
  check_grad("interpolate_rows", kTol, [idx](auto& in) { return ag::interpolate_rows(in[0], idx, in[1]); }, {x, w});
  const Tensord y = ag::interpolate_rows(x, idx, w);
  double e = 0;
  for (int k = 0; k < 3; ++k) e += w.at(2, k) * x.at(idx[2 * 3 + k], 1);
  CHECK(y.at(2, 1) == doctest::Approx(e));
}

TEST_CASE("index: complex gather, scatter and interpolate") {
  const Tensord re = randn({5, 2}, 6), im = randn({5, 2}, 7), wr = randn({4, 2}, 8), wi = randn({4, 2}, 9);
  const ag::Index g{1, 1, 4, 0}, s{0, 2, 2, 1, 0}, ip = rand_index(8, 5, 10);
  check_grad("complex gather+scatter", kTol,
             [g, s](auto& in) {
               const auto z = cplx(in[0], in[1]);
               return split(ag::index_select_rows(ag::scatter_add_rows(z, s, 3), {2, 0}) +
                            ag::scatter_mean_rows(ag::index_select_rows(z, g), {0, 1, 0, 1}, 2));
             },
             {re, im});
  check_grad("complex interpolate", kTol,
             [ip](auto& in) { return split(ag::interpolate_rows(cplx(in[0], in[1]), ip, cplx(in[2], in[3]))); },
             {re, im, wr, wi});
}

// The fused edge input equals the three-op composition bit for bit, value and gradients,
// also when operands are one tensor (its gradient then sums both parts).
TEST_CASE("index: add_gathered_rows is add(base, add(gather a, gather b))") {
  const Tensord base = randn({9, 4}, 51), a = randn({5, 4}, 52), b = randn({6, 4}, 53);
  const ag::Index ia{4, 0, 0, 2, 4, 4, 1, 3, 0}, ib{5, 5, 0, 1, 2, 0, 3, 3, 5};  // row 4 of b: never gathered
  check_grad("add_gathered_rows", kTol, [&](auto& in) { return ag::add_gathered_rows(in[0], in[1], ia, in[2], ib); },
             {base, a, b});
  const Tensord w = randn({9, 4}, 54);
  auto run = [&](bool fused, bool same) {
    Tensord x = base.detach().set_requires_grad(true), p = a.detach().set_requires_grad(true),
            q = b.detach().set_requires_grad(true);
    const Tensord& qq = same ? p : q;
    const ag::Index& jb = same ? ia : ib;
    const Tensord y = fused ? ag::add_gathered_rows(x, p, ia, qq, jb)
                            : ag::add(x, ag::add(ag::index_select_rows(p, ia), ag::index_select_rows(qq, jb)));
    sum(ag::mul(y, w)).backward();
    std::vector<double> r = ag::to_vector(y.values());
    for (const Tensord* t : {&x, &p, &q})
      if (t->has_grad()) r.insert(r.end(), t->grad().begin(), t->grad().end());
    return r;
  };
  CHECK(run(true, false) == run(false, false));
  CHECK(run(true, true) == run(false, true));
  CHECK_THROWS_WITH_AS(ag::add_gathered_rows(base, a, {0, 1}, b, ib), doctest::Contains("indices"), ag::Error);
  CHECK_THROWS_WITH_AS(ag::add_gathered_rows(base, randn({5, 3}, 55), ia, b, ib), doctest::Contains("widths"),
                       ag::Error);
  CHECK_THROWS_AS(ag::add_gathered_rows(base, a, ib, b, ib), ag::Error);  // 5 is outside a's 5 rows
}

TEST_CASE("index: out-of-range indices are refused") {
  const Tensord x = randn({3, 2}, 11);
  CHECK_THROWS_WITH_AS(ag::index_select_rows(x, {0, 3}), doctest::Contains("index_select_rows"), ag::Error);
  CHECK_THROWS_AS(ag::scatter_add_rows(x, {0, 1, 5}, 4), ag::Error);
  CHECK_THROWS_AS(ag::scatter_add_rows(x, {0, 1}, 4), ag::Error);  // wrong count
  CHECK_THROWS_AS(ag::interpolate_rows(x, {0, 1, 2}, randn({2, 2}, 12)), ag::Error);
}

TEST_CASE("index: large parallel gather/scatter agree with a serial reference") {
  const int64_t R = 3000, N = 20000, C = 8;
  const Tensord x = randn({N, C}, 13);
  const ag::Index idx = rand_index(N, R, 14);
  const Tensord s = ag::scatter_add_rows(x, idx, R);
  Eigen::MatrixXd ref = Eigen::MatrixXd::Zero(R, C);
  for (int64_t i = 0; i < N; ++i) ref.row(idx[i]) += x.mat().row(i);
  CHECK((s.mat() - ref).cwiseAbs().maxCoeff() < 1e-12);
  Tensord xl = x.detach().set_requires_grad(true);
  const Tensord w = randn({R, C}, 15);
  sum(ag::scatter_add_rows(xl, idx, R) * w).backward();
  double err = 0;
  for (int64_t i = 0; i < N; ++i)
    for (int64_t j = 0; j < C; ++j) err = std::max(err, std::abs(xl.grad()[i * C + j] - w.at(idx[i], j)));
  CHECK(err == 0.0);
}

namespace {
// All scatter-type results of one graph of gathers and scatters, with a given thread count.
std::vector<std::vector<double>> scatter_results(int threads) {
  const int64_t R = 2000, N = 30000, C = 16;
  const Tensord x0 = randn({N, C}, 41), v0 = randn({R, C}, 42), w0 = randu({N, 3}, 43, 0.0, 1.0);
  const ag::Index idx = rand_index(N, R, 44), tri = rand_index(N * 3, R, 45);
  omp_set_num_threads(threads);
  Tensord x = x0.detach().set_requires_grad(true), v = v0.detach().set_requires_grad(true),
          w = w0.detach().set_requires_grad(true);
  const Tensord s = ag::scatter_add_rows(x, idx, R), m = ag::scatter_mean_rows(x, idx, R);
  const Tensord gsel = ag::index_select_rows(v, idx), ip = ag::interpolate_rows(v, tri, w);
  const Tensord c = randn({N, C}, 46);
  (ag::sum(ag::mul(s, s)) + ag::sum(m) + ag::sum(ag::mul(ag::index_select_rows(s, idx) + gsel + ip, c))).backward();
  omp_set_num_threads(omp_get_num_procs());
  return {ag::to_vector(s.values()), ag::to_vector(m.values()), ag::to_vector(x.grad()), ag::to_vector(v.grad()),
          ag::to_vector(w.grad())};
}
}  // namespace

TEST_CASE("index: scatters are deterministic across thread counts and sum in index order") {
  const auto r1 = scatter_results(1), r2 = scatter_results(2);
  REQUIRE(r1.size() == r2.size());
  for (size_t k = 0; k < r1.size(); ++k) CHECK(r1[k] == r2[k]);  // bit for bit
  // The segment sum adds each receiver's rows in increasing source order, as a serial loop.
  const int64_t R = 2000, N = 30000, C = 16;
  const Tensord x = randn({N, C}, 41);
  const ag::Index idx = rand_index(N, R, 44);
  std::vector<double> ref(static_cast<size_t>(R * C), 0.0);
  for (int64_t i = 0; i < N; ++i)
    for (int64_t j = 0; j < C; ++j) ref[idx[i] * C + j] += x.data()[i * C + j];
  CHECK(r1[0] == ref);
}

// ImplicitBending (the backward-Euler bending step of the cloth solver), checked against its
// definition, both ways of solving it (the factorisation; Jacobi iteration where the mass
// dominates): the solve's x must satisfy M (x - y) + h^2 grad E(x) = 0 at every free vertex,
// with E = sum_b stiffness_b |sum_k K_bk x_bk|^2 / 2 evaluated here from the stencils (not from
// the solver's assembled matrix), and the fixed vertices left where they were.
#include <doctest/doctest.h>

#include "tests/support/omp_threads.hpp"

#include "gdsr/sim/cloth_bending_solve.hpp"
#include "gdsr/error.hpp"

#include <omp.h>

#include <cmath>
#include <random>
#include <vector>

using gdsr::Points3;
using gdsr::Vec3;

namespace {

// An n x n grid sheet, 10 mm apart, with a stencil on every cell (its four corners, weights
// (1, 1, -1, -1) perturbed: the weights of a real hinge sum to zero, these need not) and the
// first row fixed; positions jittered by a few mm. The stiffnesses (N/m) make h^2 K / m about 1
// at h = 1/600 s: bending and inertia weigh alike in the solve.
struct Sheet {
  int n;
  std::vector<sim::BendStencil> bends;
  std::vector<double> mass;
  std::vector<char> fixed;
  Points3 y;
};

Sheet make_sheet(int n, unsigned seed) {
  Sheet s{n, {}, std::vector<double>(n * n, 1e-3), std::vector<char>(n * n, 0), Points3(n * n, 3)};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-3e-3, 3e-3), weight(-0.2, 0.2), stiff(200, 800);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) s.y.row(i * n + j) << 0.01 * j + jitter(rng), 0.01 * i + jitter(rng), jitter(rng);
  for (int j = 0; j < n; ++j) s.fixed[j] = 1;
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j + 1 < n; ++j) {
      const int a = i * n + j;
      s.bends.push_back({{a, a + n + 1, a + 1, a + n},
                         {1 + weight(rng), 1 + weight(rng), -1 + weight(rng), -1 + weight(rng)},
                         stiff(rng)});
    }
  return s;
}

// The same sheet with the mass 50 times heavier: the mass dominates (ImplicitBending::
// dominance_ratio 0.39 / 0.46 for n = 10 / 70 at h = 1/600 s, as on the 10 mm t-shirt at about
// 1/1000 s), so the solve takes Jacobi iteration (18 / 22 sweeps).
Sheet heavy_sheet(int n, unsigned seed) {
  Sheet s = make_sheet(n, seed);
  for (double& m : s.mass) m *= 50;
  return s;
}

// Largest |M (x - y) + h^2 grad E(x)| over the free vertices, relative to the largest
// |M (x - y)|; and the largest move of a fixed vertex.
void residual(const Sheet& s, double h, const Points3& x, double& rel, double& fixed_move) {
  Points3 r = Points3::Zero(x.rows(), 3);
  for (int v = 0; v < x.rows(); ++v) r.row(v) = s.mass[v] * (x.row(v) - s.y.row(v));
  const double scale = r.rowwise().norm().maxCoeff();
  for (const auto& b : s.bends) {
    Vec3 q = Vec3::Zero();
    for (int k = 0; k < 4; ++k) q += b.K[k] * x.row(b.v[k]).transpose();
    for (int k = 0; k < 4; ++k) r.row(b.v[k]) += (h * h * b.stiffness * b.K[k]) * q.transpose();
  }
  rel = 0;
  fixed_move = 0;
  for (int v = 0; v < x.rows(); ++v) {
    if (s.fixed[v])
      fixed_move = std::max(fixed_move, (x.row(v) - s.y.row(v)).norm());
    else
      rel = std::max(rel, r.row(v).norm() / scale);
  }
}

}  // namespace

TEST_CASE("implicit bending: the solve satisfies M (x - y) + h^2 grad E(x) = 0, on one thread and on two") {
  const sim::TwoOmpThreads threads;
  // 10 x 10 runs on one thread; 70 x 70 (4,830 free vertices) on two (the solve shares the
  // x, y and z substitutions out from 4,096 free vertices).
  for (int n : {10, 70}) {
    CAPTURE(n);
    const Sheet s = make_sheet(n, 7);
    sim::ImplicitBending bending(n * n, s.bends, s.mass, s.fixed);
    for (double h : {1.0 / 600, 1.0 / 60}) {  // the second call factors again
      CAPTURE(h);
      Points3 x = s.y;
      bending.solve(h, x);
      double rel = 1, fixed_move = 1;
      residual(s, h, x, rel, fixed_move);
      CHECK(rel < 1e-9);
      CHECK(fixed_move == 0);
      CHECK((x - s.y).norm() > 1e-6);  // the bending did move the sheet
    }
  }
}

TEST_CASE("implicit bending: the two-thread solve gives the one-thread result bit for bit, factorised or by Jacobi") {
  const sim::TwoOmpThreads threads;
  for (bool heavy : {false, true}) {
    CAPTURE(heavy);
    const Sheet s = heavy ? heavy_sheet(70, 11) : make_sheet(70, 11);
    sim::ImplicitBending bending(70 * 70, s.bends, s.mass, s.fixed);
    Points3 two = s.y, one = s.y;
    bending.solve(1.0 / 600, two);
    CHECK((bending.last_iterations() > 0) == heavy);  // Jacobi on the heavy sheet only
    // Called from inside a parallel region with nesting off, the solve's own region gets one
    // thread, which runs the six substitutions in turn, or every row of each Jacobi sweep.
    const int levels = omp_get_max_active_levels();
    omp_set_max_active_levels(1);
    int outer = 0;
#pragma omp parallel num_threads(2)
    {
      if (omp_get_thread_num() == 0) {
        outer = omp_get_num_threads();
        bending.solve(1.0 / 600, one);
      }
    }
    omp_set_max_active_levels(levels);
    CHECK(outer == 2);  // else the inner region was not the nested, one-thread one
    CHECK((two - one).cwiseAbs().maxCoeff() == 0.0);
  }
}

TEST_CASE("implicit bending: a factorisation kept per substep length gives a fresh one's result bit for bit") {
  // Adaptive substeps (SimParams::substep_travel) alternate substep lengths between frames.
  const Sheet s = make_sheet(30, 5);
  sim::ImplicitBending kept(30 * 30, s.bends, s.mass, s.fixed), fresh(30 * 30, s.bends, s.mass, s.fixed);
  Points3 a = s.y, b = s.y, c = s.y;
  kept.solve(1.0 / 600, a);
  kept.solve(1.0 / 1200, b);
  kept.solve(1.0 / 600, c);
  Points3 d = s.y;
  fresh.solve(1.0 / 600, d);
  CHECK((a - d).cwiseAbs().maxCoeff() == 0.0);
  CHECK((c - d).cwiseAbs().maxCoeff() == 0.0);
  CHECK((b - d).cwiseAbs().maxCoeff() > 1e-6);  // the other length is another solve
}

TEST_CASE("implicit bending: where the mass dominates, Jacobi iteration satisfies the same equation to 1e-12 m") {
  const sim::TwoOmpThreads threads;
  for (int n : {10, 70}) {  // one thread; two (from 4,096 free vertices)
    CAPTURE(n);
    const Sheet s = heavy_sheet(n, 7);
    sim::ImplicitBending jacobi(n * n, s.bends, s.mass, s.fixed), factored(n * n, s.bends, s.mass, s.fixed, 0.0);
    const double h = 1.0 / 600;
    const double ratio = jacobi.dominance_ratio(h);
    CHECK(ratio > 0.1);
    CHECK(ratio <= sim::ImplicitBending::kJacobiMaxRatio);
    Points3 x = s.y, ref = s.y;
    jacobi.solve(h, x);
    factored.solve(h, ref);
    CHECK(jacobi.last_iterations() > 2);
    CHECK(factored.last_iterations() == 0);
    double rel = 1, fixed_move = 1;
    residual(s, h, x, rel, fixed_move);
    CHECK(rel < 1e-9);  // the definition, evaluated from the stencils
    CHECK(fixed_move == 0);
    CHECK((x - s.y).cwiseAbs().maxCoeff() > 1e-5);  // the bending did move the sheet
    // The promised accuracy, against the factorisation (itself exact to rounding).
    CHECK((x - ref).cwiseAbs().maxCoeff() < sim::ImplicitBending::kJacobiTolerance);
  }
}

TEST_CASE("implicit bending: stiff bending or a long substep takes the factorisation, not Jacobi") {
  const Sheet s = make_sheet(10, 3);  // h^2 K / m about 1 at h = 1/600 s
  sim::ImplicitBending bending(100, s.bends, s.mass, s.fixed);
  CHECK(bending.dominance_ratio(1.0 / 600) > sim::ImplicitBending::kJacobiMaxRatio);
  Points3 x = s.y;
  bending.solve(1.0 / 600, x);
  CHECK(bending.last_iterations() == 0);
  // The heavy sheet, with substeps ten times longer: the ratio grows with h^2.
  const Sheet heavy = heavy_sheet(10, 3);
  sim::ImplicitBending slow(100, heavy.bends, heavy.mass, heavy.fixed);
  CHECK(slow.dominance_ratio(1.0 / 600) < slow.dominance_ratio(1.0 / 60));
  CHECK(slow.dominance_ratio(1.0 / 60) > sim::ImplicitBending::kJacobiMaxRatio);
  Points3 y = heavy.y;
  slow.solve(1.0 / 60, y);
  CHECK(slow.last_iterations() == 0);
  double rel = 1, fixed_move = 1;
  residual(heavy, 1.0 / 60, y, rel, fixed_move);
  CHECK(rel < 1e-9);
}

TEST_CASE("implicit bending: bad inputs are refused with a message naming the problem") {
  const Sheet s = make_sheet(4, 3);
  CHECK_THROWS_WITH(sim::ImplicitBending(15, s.bends, s.mass, s.fixed), doctest::Contains("one entry per vertex"));
  std::vector<double> massless = s.mass;
  massless[5] = 0;
  CHECK_THROWS_WITH(sim::ImplicitBending(16, s.bends, massless, s.fixed), doctest::Contains("has no mass"));
  std::vector<sim::BendStencil> negative = s.bends;
  negative[0].stiffness = -1;
  CHECK_THROWS_WITH(sim::ImplicitBending(16, negative, s.mass, s.fixed), doctest::Contains(">= 0"));
  CHECK_THROWS_WITH(sim::ImplicitBending(16, s.bends, s.mass, s.fixed, 1.0), doctest::Contains("[0, 1)"));
  CHECK_THROWS_WITH(sim::ImplicitBending(16, s.bends, s.mass, s.fixed, -0.1), doctest::Contains("[0, 1)"));
}

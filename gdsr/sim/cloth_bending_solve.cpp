#include "gdsr/sim/cloth_bending_solve.hpp"

#include "gdsr/error.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <omp.h>

namespace sim {

struct ImplicitBending::Impl {
  std::vector<int> free_index;  // vertex -> row among the free vertices, -1 when fixed
  std::vector<int> free_vertex;  // row -> vertex
  std::vector<double> mass;      // per free row, kg
  Eigen::SparseMatrix<double> Q_ff, Q_fp;  // bending Hessian blocks: free x free, free x all vertices (fixed cols only)
  Eigen::VectorXd Q_diag;                  // diagonal of Q_ff
  using Factor = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>;
  // What a substep length h solves with: Jacobi iteration when M + h^2 Q_ff is diagonally
  // dominant enough (see ImplicitBending::dominance_ratio), else the factorisation.
  struct Step {
    double ratio = 0;                // max over rows of (sum of |off-diagonal|) / diagonal
    double stop = 0;                 // Jacobi ends when no coordinate moves by more: see solve
    Eigen::VectorXd inv_diag;        // 1 / (m + h^2 Q_ii), for Jacobi
    std::unique_ptr<Factor> factor;  // for the others
  };
  // One per substep length h seen (SimParams::substep_travel varies it between frames).
  std::map<double, Step> steps;
  int last_iterations = 0;
  double jacobi_max_ratio = 0;
  Step& step(double h);  // steps[h], made on first use
};

ImplicitBending::ImplicitBending(int nv, const std::vector<BendStencil>& bends, const std::vector<double>& mass,
                                 const std::vector<char>& fixed, double jacobi_max_ratio)
    : impl_(std::make_unique<Impl>()) {
  if (static_cast<int>(mass.size()) != nv || static_cast<int>(fixed.size()) != nv)
    gdsr::fail("sim/cloth_bending_solve", "mass and fixed must have one entry per vertex");
  auto& I = *impl_;
  if (!(jacobi_max_ratio >= 0 && jacobi_max_ratio < 1))
    gdsr::fail("sim/cloth_bending_solve", "jacobi_max_ratio must be in [0, 1) (Jacobi converges only below 1)");
  I.jacobi_max_ratio = jacobi_max_ratio;
  I.free_index.assign(nv, -1);
  for (int v = 0; v < nv; ++v)
    if (!fixed[v]) {
      if (!(mass[v] > 0)) gdsr::fail("sim/cloth_bending_solve", "free vertex " + std::to_string(v) + " has no mass");
      I.free_index[v] = static_cast<int>(I.free_vertex.size());
      I.free_vertex.push_back(v);
      I.mass.push_back(mass[v]);
    }
  const int nf = static_cast<int>(I.free_vertex.size());
  std::vector<Eigen::Triplet<double>> ff, fp;
  for (const auto& b : bends) {
    if (!(b.stiffness >= 0)) gdsr::fail("sim/cloth_bending_solve", "bending stiffness must be >= 0");
    for (int i = 0; i < 4; ++i) {
      const int ri = I.free_index[b.v[i]];
      if (ri < 0) continue;
      for (int j = 0; j < 4; ++j) {
        const double q = b.stiffness * b.K[i] * b.K[j];
        const int cj = I.free_index[b.v[j]];
        if (cj >= 0)
          ff.emplace_back(ri, cj, q);
        else
          fp.emplace_back(ri, b.v[j], q);
      }
    }
  }
  I.Q_ff.resize(nf, nf);
  I.Q_ff.setFromTriplets(ff.begin(), ff.end());
  I.Q_fp.resize(nf, nv);
  I.Q_fp.setFromTriplets(fp.begin(), fp.end());
  I.Q_diag = I.Q_ff.diagonal();
}

ImplicitBending::~ImplicitBending() = default;

namespace {

using RowPoints = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Y := L^-T D^-1 L^-1 Y on columns c0 .. c0 + K - 1 of Y, for L unit lower triangular stored
// column by column (SimplicialLDLT's), inv_d = 1 / D: Eigen's forward (column-major lower) and
// backward (the transpose: row-major upper) sweeps and its diagonal step, the same operations
// per column in the same order, all K columns in one sweep over L.
template <int K>
void substitute(const Eigen::SparseMatrix<double>& L, const Eigen::VectorXd& inv_d, RowPoints& Y, int c0) {
  const int n = static_cast<int>(L.cols());
  const int* outer = L.outerIndexPtr();
  const int* inner = L.innerIndexPtr();
  const double* value = L.valuePtr();
  auto begin = [&](int i) {  // first entry of column i below the diagonal (Eigen skips the rest)
    int p = outer[i];
    const int end = outer[i + 1];
    while (p < end && inner[p] < i) ++p;
    if (p < end && inner[p] == i) ++p;
    return p;
  };
  for (int i = 0; i < n; ++i) {  // forward: y_r -= y_i L_ri below the diagonal, where y_i != 0
    double t[K];
    for (int c = 0; c < K; ++c) t[c] = Y(i, c0 + c);
    for (int p = begin(i), end = outer[i + 1]; p < end; ++p)
      for (int c = 0; c < K; ++c)
        if (t[c] != 0) Y(inner[p], c0 + c) -= t[c] * value[p];
  }
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < K; ++c) Y(i, c0 + c) = inv_d[i] * Y(i, c0 + c);
  for (int i = n - 1; i >= 0; --i) {  // backward: y_i -= L_ri y_r over the rows r below i
    double t[K];
    for (int c = 0; c < K; ++c) t[c] = Y(i, c0 + c);
    for (int p = begin(i), end = outer[i + 1]; p < end; ++p)
      for (int c = 0; c < K; ++c) t[c] -= value[p] * Y(inner[p], c0 + c);
    for (int c = 0; c < K; ++c) Y(i, c0 + c) = t[c];
  }
}

}  // namespace

double ImplicitBending::dominance_ratio(double h) { return impl_->step(h).ratio; }

int ImplicitBending::last_iterations() const { return impl_->last_iterations; }

ImplicitBending::Impl::Step& ImplicitBending::Impl::step(double h) {
  Impl& I = *this;
  Step& st = I.steps[h];
  if (st.inv_diag.size() == 0 && !st.factor) {
    const int nf = static_cast<int>(I.free_vertex.size());
    const double h2 = h * h;
    st.inv_diag.resize(nf);
    Eigen::VectorXd off = Eigen::VectorXd::Zero(nf);  // sum of |off-diagonal| per row (Q_ff symmetric)
    for (int i = 0; i < nf; ++i)
      for (Eigen::SparseMatrix<double>::InnerIterator q(I.Q_ff, i); q; ++q)
        if (q.index() != i) off[i] += h2 * std::abs(q.value());
    for (int i = 0; i < nf; ++i) {
      const double d = I.mass[i] + h2 * I.Q_diag[i];
      st.inv_diag[i] = 1 / d;
      st.ratio = std::max(st.ratio, off[i] / d);
    }
    st.stop = kJacobiTolerance * (1 - st.ratio) / std::max(st.ratio, 1e-300);
    if (!(st.ratio <= jacobi_max_ratio)) {
      Eigen::SparseMatrix<double> S = h2 * I.Q_ff;
      for (int r = 0; r < nf; ++r) S.coeffRef(r, r) += I.mass[r];
      st.factor = std::make_unique<Factor>(S);
      if (st.factor->info() != Eigen::Success) gdsr::fail("sim/cloth_bending_solve", "factorisation failed");
    }
  }
  return st;
}

void ImplicitBending::solve(double h, gdsr::Points3& x) {
  auto& I = *impl_;
  const int nf = static_cast<int>(I.free_vertex.size());
  I.last_iterations = 0;
  if (nf == 0) return;
  const Impl::Step& st = I.step(h);
  Eigen::MatrixXd rhs(nf, 3);
  for (int r = 0; r < nf; ++r) rhs.row(r) = I.mass[r] * x.row(I.free_vertex[r]);
  if (I.Q_fp.nonZeros() > 0) rhs -= (h * h) * (I.Q_fp * Eigen::MatrixXd(x));
  constexpr int kParallelRows = 4096;
  if (!st.factor) {
    // Jacobi from the predicted positions: y += D^-1 (rhs - (M + h^2 Q_ff) y), every row from
    // the last iterate, so rows may be shared between threads in any way with the same result
    // (and the largest update is a max, the same in any order). The error after an update u is
    // at most ratio / (1 - ratio) |u| (the iteration contracts by `ratio` in the max norm).
    const double h2 = h * h;
    RowPoints y(nf, 3), next(nf, 3);
    for (int r = 0; r < nf; ++r) y.row(r) = x.row(I.free_vertex[r]);
    const int* outer = I.Q_ff.outerIndexPtr();
    const int* inner = I.Q_ff.innerIndexPtr();
    const double* value = I.Q_ff.valuePtr();
    double largest[2] = {0, 0};
    int it = 0;
    bool done = false;
#pragma omp parallel num_threads(2) if (nf >= kParallelRows && omp_get_max_threads() > 1)
    while (!done) {
      const int t = omp_get_thread_num(), n = omp_get_num_threads();
      double d = 0;
      for (int i = nf * t / n, end = nf * (t + 1) / n; i < end; ++i) {
        double q0 = 0, q1 = 0, q2 = 0;  // (Q_ff y)_i: column i of the symmetric Q_ff
        for (int p = outer[i]; p < outer[i + 1]; ++p) {
          const double v = value[p];
          const int j = inner[p];
          q0 += v * y(j, 0), q1 += v * y(j, 1), q2 += v * y(j, 2);
        }
        const double m = I.mass[i], w = st.inv_diag[i];
        const double u0 = w * (rhs(i, 0) - m * y(i, 0) - h2 * q0);
        const double u1 = w * (rhs(i, 1) - m * y(i, 1) - h2 * q1);
        const double u2 = w * (rhs(i, 2) - m * y(i, 2) - h2 * q2);
        next(i, 0) = y(i, 0) + u0, next(i, 1) = y(i, 1) + u1, next(i, 2) = y(i, 2) + u2;
        d = std::max({d, std::abs(u0), std::abs(u1), std::abs(u2)});
      }
      largest[t] = d;
#pragma omp barrier
#pragma omp single
      {
        y.swap(next);
        ++it;
        const double moved = std::max(largest[0], largest[1]);
        // (a NaN is not seen by the max: it stays in x, where the cloth solver's finite check reports it)
        done = moved <= st.stop || it >= kMaxJacobiIterations;
        largest[0] = largest[1] = 0;
      }  // (the single's implied barrier: every thread sees y, done)
    }
    I.last_iterations = it;
    for (int r = 0; r < nf; ++r) x.row(I.free_vertex[r]) = y.row(r);
    return;
  }
  const Impl::Factor& ldlt = *st.factor;
  // x, y and z are independent solves with the same factor P^T L D L^T P. Each substitution
  // sweep reads the whole factor (memory-bound: the t-shirt's L does not fit in cache), so the
  // sweeps below take the columns together, reading L once for two or three of them, with
  // Eigen's arithmetic per column in Eigen's order (the result is SimplicialLDLT::solve's bit
  // for bit). Two threads: x and y on one, z on the other; a small mesh, all three on one
  // thread (two threads' start-up cost more than they save on an LR garment). The 15k-vertex
  // t-shirt (bench/bench_gauss_seidel.cpp): Eigen's solve, a column at a time, 14.4 ms for the
  // three on one thread; these sweeps 7.8 ms on one thread, 6.5 ms on two.
  const auto& L = ldlt.matrixL().nestedExpression();  // unit lower, column-major, strictly below the diagonal
  RowPoints sol(nf, 3);
  sol = ldlt.permutationP() * rhs;
  const Eigen::VectorXd inv_d = ldlt.vectorD().cwiseInverse();
  auto solve = [&](int c0, int k) {
    if (k == 3) substitute<3>(L, inv_d, sol, c0);
    if (k == 2) substitute<2>(L, inv_d, sol, c0);
    if (k == 1) substitute<1>(L, inv_d, sol, c0);
  };
#pragma omp parallel num_threads(2) if (nf >= kParallelRows && omp_get_max_threads() > 1)
  {
    if (omp_get_num_threads() == 1)
      solve(0, 3);
    else if (omp_get_thread_num() == 0)
      solve(0, 2);
    else
      solve(2, 1);
  }
  sol = ldlt.permutationPinv() * sol;
  for (int r = 0; r < nf; ++r) x.row(I.free_vertex[r]) = sol.row(r);
}

}  // namespace sim

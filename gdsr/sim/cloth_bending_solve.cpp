#include "gdsr/sim/cloth_bending_solve.hpp"

#include "gdsr/error.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <map>
#include <memory>
#include <omp.h>

namespace sim {

struct ImplicitBending::Impl {
  std::vector<int> free_index;  // vertex -> row among the free vertices, -1 when fixed
  std::vector<int> free_vertex;  // row -> vertex
  std::vector<double> mass;      // per free row, kg
  Eigen::SparseMatrix<double> Q_ff, Q_fp;  // bending Hessian blocks: free x free, free x all vertices (fixed cols only)
  using Factor = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>;
  // One per substep length h seen (SimParams::substep_travel varies it between frames).
  std::map<double, std::unique_ptr<Factor>> factors;
};

ImplicitBending::ImplicitBending(int nv, const std::vector<BendStencil>& bends, const std::vector<double>& mass,
                                 const std::vector<char>& fixed)
    : impl_(std::make_unique<Impl>()) {
  if (static_cast<int>(mass.size()) != nv || static_cast<int>(fixed.size()) != nv)
    gdsr::fail("sim/cloth_bending_solve", "mass and fixed must have one entry per vertex");
  auto& I = *impl_;
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

void ImplicitBending::solve(double h, gdsr::Points3& x) {
  auto& I = *impl_;
  const int nf = static_cast<int>(I.free_vertex.size());
  if (nf == 0) return;
  std::unique_ptr<Impl::Factor>& factor = I.factors[h];
  if (!factor) {
    Eigen::SparseMatrix<double> S = (h * h) * I.Q_ff;
    for (int r = 0; r < nf; ++r) S.coeffRef(r, r) += I.mass[r];
    factor = std::make_unique<Impl::Factor>(S);
    if (factor->info() != Eigen::Success) gdsr::fail("sim/cloth_bending_solve", "factorisation failed");
  }
  const Impl::Factor& ldlt = *factor;
  Eigen::MatrixXd rhs(nf, 3);
  for (int r = 0; r < nf; ++r) rhs.row(r) = I.mass[r] * x.row(I.free_vertex[r]);
  if (I.Q_fp.nonZeros() > 0) rhs -= (h * h) * (I.Q_fp * Eigen::MatrixXd(x));
  // x, y and z are independent solves with the same factor P^T L D L^T P. Each substitution
  // sweep reads the whole factor (memory-bound: the t-shirt's L does not fit in cache), so the
  // sweeps below take the columns together, reading L once for two or three of them, with
  // Eigen's arithmetic per column in Eigen's order (the result is SimplicialLDLT::solve's bit
  // for bit). Two threads: x and y on one, z on the other; a small mesh, all three on one
  // thread (two threads' start-up cost more than they save on an LR garment). The 15k-vertex
  // t-shirt (bench/bench_gauss_seidel.cpp): Eigen's solve, a column at a time, 14.4 ms for the
  // three on one thread; these sweeps 7.8 ms on one thread, 6.5 ms on two.
  constexpr int kParallelRows = 4096;
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

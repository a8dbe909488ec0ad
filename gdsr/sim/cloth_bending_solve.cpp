#include "gdsr/sim/cloth_bending_solve.hpp"

#include "gdsr/error.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace sim {

struct ImplicitBending::Impl {
  std::vector<int> free_index;  // vertex -> row among the free vertices, -1 when fixed
  std::vector<int> free_vertex;  // row -> vertex
  std::vector<double> mass;      // per free row, kg
  Eigen::SparseMatrix<double> Q_ff, Q_fp;  // bending Hessian blocks: free x free, free x all vertices (fixed cols only)
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  double h = 0;  // substep the factorisation is for
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

void ImplicitBending::solve(double h, gdsr::Points3& x) {
  auto& I = *impl_;
  const int nf = static_cast<int>(I.free_vertex.size());
  if (nf == 0) return;
  if (h != I.h) {
    Eigen::SparseMatrix<double> S = (h * h) * I.Q_ff;
    for (int r = 0; r < nf; ++r) S.coeffRef(r, r) += I.mass[r];
    I.ldlt.compute(S);
    if (I.ldlt.info() != Eigen::Success) gdsr::fail("sim/cloth_bending_solve", "factorisation failed");
    I.h = h;
  }
  Eigen::MatrixXd rhs(nf, 3);
  for (int r = 0; r < nf; ++r) rhs.row(r) = I.mass[r] * x.row(I.free_vertex[r]);
  if (I.Q_fp.nonZeros() > 0) rhs -= (h * h) * (I.Q_fp * Eigen::MatrixXd(x));
  // x, y and z are independent solves with the same factor: one per thread (the same
  // arithmetic as one three-column solve, so the result does not depend on the thread count).
  Eigen::MatrixXd sol(nf, 3);
#pragma omp parallel for schedule(static)
  for (int c = 0; c < 3; ++c) sol.col(c) = I.ldlt.solve(rhs.col(c));
  for (int r = 0; r < nf; ++r) x.row(I.free_vertex[r]) = sol.row(r);
}

}  // namespace sim

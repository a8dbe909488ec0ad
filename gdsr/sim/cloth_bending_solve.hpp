// Implicit isometric bending: one sparse linear solve per substep instead of Gauss-Seidel
// passes over the bending constraints.
//
// Why: the isometric bending energy (Bergou et al. 2006) is quadratic in the positions,
//   E(x) = sum_b |sum_k K_bk x_bk|^2 * stiffness_b / 2,   i.e.  E = x^T Q x / 2 per coordinate,
// with a constant Q. Local Gauss-Seidel passes propagate bending only a few edges per pass,
// so a 10 mm mesh (3x more edges along a strip than a 30 mm one) ends up far softer than the
// same fabric at 30 mm (a cantilever at 10 mm hung almost vertically where the heavy
// elastica says 42 degrees). The backward-Euler step of inertia plus this energy,
//   (M + h^2 Q) x = M y,      y = the predicted positions,
// is exact for the bending part at any resolution, and its matrix is constant for a substep
// length h. Solved to 1e-12 m, one of two ways per h: where the mass dominates (a short
// substep, a coarse mesh: LR always, HR on fast clips) by Jacobi iteration, a few sweeps over
// Q; else factored once per h (sparse LDL^T), each substep one forward/back substitution for
// the three coordinates. On the 10 mm t-shirt on walk 131_01 (12,858 free vertices, about 30
// substeps a frame, 2 threads) the factorisation took 8.0 ms a solve, Jacobi 1.8 ms (13.5 sweeps
// on average, to 1e-12 m); bench/bench_gauss_seidel.cpp times both. Fixed (pinned) vertices keep
// their positions and enter the right-hand side. Deterministic on any thread count.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <memory>
#include <vector>

namespace sim {

struct BendStencil {
  int v[4];          // vertex ids: the hinge edge (v0, v1) and the two opposite vertices
  double K[4];       // dimensionless weights (cotangents): q_b = sum_k K[k] x[v[k]] is in metres
  double stiffness;  // N/m: E_b = stiffness |q_b|^2 / 2 joules (bending modulus / hinge area)
};

class ImplicitBending {
 public:
  // mass: kg per vertex (> 0 for free vertices); fixed[v] != 0: vertex v is pinned.
  // jacobi_max_ratio: see below (0: always the factorisation).
  ImplicitBending(int num_vertices, const std::vector<BendStencil>& bends, const std::vector<double>& mass,
                  const std::vector<char>& fixed, double jacobi_max_ratio = kJacobiMaxRatio);
  ~ImplicitBending();
  ImplicitBending(const ImplicitBending&) = delete;
  ImplicitBending& operator=(const ImplicitBending&) = delete;

  // x: predicted positions of the free vertices and current positions of the fixed ones
  // (metres); replaces the free rows by the solution of (M + h^2 Q) x = M y for a substep of
  // h seconds. A factorisation is computed on the first call with each h and kept.
  void solve(double h, gdsr::Points3& x);

  // How the solve is made for a substep length h. Let ratio be the largest, over the free rows,
  // of the row's summed |off-diagonal| entries over its diagonal in M + h^2 Q (< 1: strictly
  // diagonally dominant). When ratio <= jacobi_max_ratio, Jacobi iteration from y: each
  // iteration shrinks the error in the max norm by at least that ratio, so it stops when no
  // coordinate moves by more than kJacobiTolerance (1 - ratio) / ratio metres, which leaves an
  // error below kJacobiTolerance. Else (stiff bending, long substeps, fine meshes) the sparse
  // LDL^T above. dominance_ratio(h): that ratio (computed and kept per h).
  static constexpr double kJacobiMaxRatio = 0.75;
  static constexpr double kJacobiTolerance = 1e-12;  // metres
  static constexpr int kMaxJacobiIterations = 1000;  // a safeguard (0.9^1000 = 1e-46)
  double dominance_ratio(double h);
  // Jacobi iterations of the last solve (0: solved by the factorisation).
  int last_iterations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sim

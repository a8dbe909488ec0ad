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
// length h, so it is factored once per h (sparse LDL^T) and each substep costs one
// forward/back substitution for the three coordinates. Fixed (pinned) vertices keep their positions and enter the
// right-hand side. Deterministic (sequential factorisation and solves).
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
  ImplicitBending(int num_vertices, const std::vector<BendStencil>& bends, const std::vector<double>& mass,
                  const std::vector<char>& fixed);
  ~ImplicitBending();
  ImplicitBending(const ImplicitBending&) = delete;
  ImplicitBending& operator=(const ImplicitBending&) = delete;

  // x: predicted positions of the free vertices and current positions of the fixed ones
  // (metres); replaces the free rows by the solution of (M + h^2 Q) x = M y for a substep of
  // h seconds. A factorisation is computed on the first call with each h and kept.
  void solve(double h, gdsr::Points3& x);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sim

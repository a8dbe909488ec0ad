// Cloth in self-contact for self-collision tests and benchmarks: two square sheets merged into
// one garment mesh, crumpled against each other.
#pragma once

#include "tests/support/square_cloth.hpp"

#include <random>

namespace gdsr_test {

// Two meshes as one garment (UV of b shifted so the pattern pieces do not overlap).
inline gdsr::GarmentMesh merge_garment_meshes(const gdsr::GarmentMesh& a, const gdsr::GarmentMesh& b) {
  gdsr::GarmentMesh m;
  const int nv = static_cast<int>(a.V.rows()), nuv = static_cast<int>(a.UV.rows());
  m.V.resize(nv + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.UV.resize(nuv + b.UV.rows(), 2);
  m.UV << a.UV, (b.UV.rowwise() + Eigen::RowVector2d(10, 0));
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, (b.F.array() + nv).matrix();
  m.FUV.resize(a.FUV.rows() + b.FUV.rows(), 3);
  m.FUV << a.FUV, (b.FUV.array() + nuv).matrix();
  m.uv_to_vertex = a.uv_to_vertex;
  for (int u : b.uv_to_vertex) m.uv_to_vertex.push_back(u + nv);
  return m;
}

// Two crumpled square sheets at 10 mm: side metres, `gap` metres apart (the second sheet above),
// random offsets up to `jitter` metres per axis; with random motions (up to 2 mm per axis).
struct CrumpledSheets {
  gdsr::GarmentMesh m;
  gdsr::Points3 x, motion;
  explicit CrumpledSheets(unsigned seed, double side = 0.2, double gap = 0.004, double jitter = 0.003)
      : m(merge_garment_meshes(square_cloth(side, 0.01, 0.0).mesh, square_cloth(side, 0.01, gap).mesh)) {
    const int nv = static_cast<int>(m.V.rows());
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    x = m.V;
    motion.resize(nv, 3);
    for (int v = 0; v < nv; ++v) {
      x.row(v) += jitter * Eigen::RowVector3d(u(rng), u(rng), u(rng));
      motion.row(v) = 0.002 * Eigen::RowVector3d(u(rng), u(rng), u(rng));
    }
  }
};

}  // namespace gdsr_test

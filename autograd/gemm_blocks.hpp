// Internal to the ops with GEMMs (ops_matmul.cpp, ops_conv.cpp): threading of Eigen products.
//
// Eigen's own GEMM threading makes its threads spin-wait on each other between panels; with
// another process on one of the cores, a descheduled thread stalls the others, and every
// product pays a time slice (measured: 64% of a small training step's CPU time in those
// spin loops under load). Instead the destination's rows are cut into blocks whose size
// depends on the shapes only (results then do not depend on the thread count), computed in
// an OpenMP loop with dynamic scheduling, one serial Eigen product per block. Eigen's
// threading is switched off once (Eigen::setNbThreads(1), process-wide) so that small
// products that are not split do not start it either.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>

namespace ag::gemm {

// Calls block(r0, r1) for the rows [0, M) of a product's destination; work_per_row is the
// multiply-adds per destination row (sets a block size of ~2M multiply-adds, >= 16 rows).
template <class F> void row_blocks(int64_t M, int64_t work_per_row, F&& block) {
  static const bool eigen_serial = (Eigen::setNbThreads(1), true);
  (void)eigen_serial;
  const int64_t w = std::max<int64_t>(1, work_per_row);
  int64_t rb = std::max<int64_t>(16, (int64_t(1) << 21) / w);
  rb = (rb + 15) / 16 * 16;
  const int64_t nb = (M + rb - 1) / rb;
  if (nb <= 1) {
    block(int64_t(0), M);
    return;
  }
#pragma omp parallel for schedule(dynamic, 1)
  for (int64_t b = 0; b < nb; ++b) block(b * rb, std::min(M, (b + 1) * rb));
}

}  // namespace ag::gemm

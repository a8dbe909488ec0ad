// Internal to the ops with GEMMs (ops_matmul.cpp, ops_conv.cpp): threading of Eigen products.
//
// Eigen's own GEMM threading makes its threads spin-wait on each other between panels; with
// another process on one of the cores, a descheduled thread stalls the others, and every
// product pays a time slice (measured: 64% of a small training step's CPU time in those
// spin loops under load). Instead the destination is cut into tiles whose size depends on
// the shapes only (results then do not depend on the thread count), computed in an OpenMP
// loop with dynamic scheduling, one serial Eigen product per tile. Eigen's threading is
// switched off once (Eigen::setNbThreads(1), process-wide) so that small products that are
// not split do not start it either.
//
// Tiles are at least 256 rows (or all of them) and 128 columns: each Eigen call packs its
// whole right-hand side block again, so thin row blocks of a wide product (A's 256 -> 17,091
// projections, cut into 16-row blocks before) spent as much time packing as multiplying
// (measured: 16-row blocks at 35-60% of one whole product's rate, 256 x 256 tiles at 90-100%).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>

namespace ag::gemm {

struct Tiling {
  int64_t row_block, col_block, row_tiles, col_tiles;
};

// The tiles of an M x N destination with inner size K: ~2M multiply-adds per tile at least,
// tiles of more than ~128M multiply-adds cut into columns of ~64M.
inline Tiling tiling(int64_t M, int64_t N, int64_t K) {
  constexpr int64_t kMinRows = 256, kMinCols = 128, kSplit = int64_t(1) << 27, kTile = int64_t(1) << 26;
  auto round16 = [](int64_t v) { return (v + 15) / 16 * 16; };
  M = std::max<int64_t>(1, M), N = std::max<int64_t>(1, N), K = std::max<int64_t>(1, K);
  int64_t rb = std::min(M, round16(std::max(kMinRows, (int64_t(1) << 21) / (N * K))));
  int64_t cb = N;
  if (rb * N * K > kSplit) cb = std::min(N, round16(std::max(kMinCols, kTile / (rb * K))));
  return {rb, cb, (M + rb - 1) / rb, (N + cb - 1) / cb};
}

// Calls block(r0, r1, c0, c1) for the tiles [r0, r1) x [c0, c1) of a product's M x N
// destination with inner size K, in parallel when there is more than one tile.
template <class F> void tiles(int64_t M, int64_t N, int64_t K, F&& block) {
  static const bool eigen_serial = (Eigen::setNbThreads(1), true);
  (void)eigen_serial;
  if (M <= 0 || N <= 0) return;
  const Tiling t = tiling(M, N, K);
  const int64_t n = t.row_tiles * t.col_tiles;
  if (n <= 1) {
    block(int64_t(0), M, int64_t(0), N);
    return;
  }
#pragma omp parallel for schedule(dynamic, 1)
  for (int64_t i = 0; i < n; ++i) {
    const int64_t r = i / t.col_tiles, c = i % t.col_tiles;
    block(r * t.row_block, std::min(M, (r + 1) * t.row_block), c * t.col_block, std::min(N, (c + 1) * t.col_block));
  }
}

}  // namespace ag::gemm

// Small garment meshes and temp folders for the data tests (header only, test code).
#pragma once

#include "gdsr/mesh.hpp"

#include <cmath>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace gdsr_test {

// A rectangular panel of nx x ny quads (two triangles each, diagonals alternating), UV in
// [0, w] x [0, h] metres. In 3-D the panel is bent about the y axis by `bend` radians in
// total (0 = planar, in the z = 0 plane) on a cylinder whose circumference matches.
// wrap = true closes it into a tube (bend must be 2 pi): the last column is welded to the
// first in 3-D, so that seam has two UV copies per vertex.
inline gdsr::GarmentMesh grid_garment(int nx, int ny, double w, double h, double bend = 0.0, bool wrap = false) {
  gdsr::GarmentMesh g;
  const int cols = nx + 1, rows = ny + 1;
  g.UV.resize(cols * rows, 2);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) g.UV.row(j * cols + i) << w * i / nx, h * j / ny;
  const int vcols = wrap ? nx : cols;
  g.V.resize(vcols * rows, 3);
  const double radius = bend > 0 ? w / bend : 0;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < vcols; ++i) {
      const double u = w * i / nx, y = h * j / ny;
      if (bend > 0) {
        const double a = u / radius;
        g.V.row(j * vcols + i) << radius * std::sin(a), y, radius * (1 - std::cos(a));
      } else {
        g.V.row(j * vcols + i) << u, y, 0.0;
      }
    }
  g.uv_to_vertex.resize(cols * rows);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) g.uv_to_vertex[j * cols + i] = j * vcols + (wrap && i == nx ? 0 : i);
  g.F.resize(2 * nx * ny, 3);
  g.FUV.resize(2 * nx * ny, 3);
  int f = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * cols + i, b = a + 1, c = a + cols, d = c + 1;
      if ((i + j) % 2 == 0) {
        g.FUV.row(f++) << a, b, d;
        g.FUV.row(f++) << a, d, c;
      } else {
        g.FUV.row(f++) << a, b, c;
        g.FUV.row(f++) << b, d, c;
      }
    }
  for (int t = 0; t < g.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) g.F(t, k) = g.uv_to_vertex[g.FUV(t, k)];
  return g;
}

// A fresh empty folder under the system temp dir, removed on destruction.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& name) {
    path = std::filesystem::temp_directory_path() / ("gdsr_test_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

}  // namespace gdsr_test

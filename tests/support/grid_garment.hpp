// The one grid-garment fixture of the tests and benchmarks: a rectangular panel of
// nx x ny quads (two triangles each), UV = the flat panel in metres, placed in 3-D as a flat
// sheet (z = 0 facing +z, or y = offset facing +y), bent about the y axis, or closed into a
// tube. Build the spec with the chainable setters:
//   grid_garment(GridSpec(6, 3, 0.6, 0.3))                 // flat, alternating diagonals
//   grid_garment(GridSpec(8, 3, 0.9, 0.3).tube())          // a tube with a UV seam
//   grid_garment(GridSpec::spaced(5, 0.03))                // 5 x 5 vertices, 3 cm apart
//   grid_garment(GridSpec::square(4, 0.2).xz(0.0).layer(1))  // in the x-z plane, normal +y
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <cmath>

namespace gdsr_test {

struct GridSpec {
  enum class Diagonals { Alternating, Rising, Falling };
  int nx, ny;             // quads along u and v
  double w, h;            // UV size, metres
  double spacing = 0;     // > 0: u = i spacing, v = j spacing exactly (instead of w i / nx)
  double bend = 0;        // radians bent about the y axis (0: flat)
  bool wrap = false;      // bend = 2 pi and the last column welded to the first (UV seam)
  bool plane_xz = false;  // 3-D (u, offset, v) facing +y instead of (u, v, 0) facing +z
  double offset = 0;      // with plane_xz: the height y
  int layer_id = -1;      // >= 0: every vertex gets this layer id
  Diagonals diagonals = Diagonals::Alternating;

  GridSpec(int nx_, int ny_, double w_, double h_) : nx(nx_), ny(ny_), w(w_), h(h_) {}
  // n x n vertices `spacing` apart, every quad split along its rising diagonal.
  static GridSpec spaced(int n, double spacing) {
    GridSpec s(n - 1, n - 1, (n - 1) * spacing, (n - 1) * spacing);
    s.spacing = spacing;
    s.diagonals = Diagonals::Rising;
    return s;
  }
  // n x n vertices over a square of side `size` in the x-z plane (y = 0), normal +y, every
  // quad split along its falling diagonal, all vertices on layer 0.
  static GridSpec square(int n, double size) {
    GridSpec s(n - 1, n - 1, size, size);
    s.plane_xz = true;
    s.layer_id = 0;
    s.diagonals = Diagonals::Falling;
    return s;
  }
  GridSpec& bent(double radians) {
    bend = radians;
    return *this;
  }
  GridSpec& tube() {
    bend = 2 * M_PI;
    wrap = true;
    return *this;
  }
  GridSpec& xz(double y) {
    plane_xz = true;
    offset = y;
    return *this;
  }
  GridSpec& layer(int id) {
    layer_id = id;
    return *this;
  }
};

inline gdsr::GarmentMesh grid_garment(const GridSpec& s) {
  gdsr::GarmentMesh g;
  const int cols = s.nx + 1, rows = s.ny + 1, vcols = s.wrap ? s.nx : cols;
  auto u_of = [&](int i) { return s.spacing > 0 ? i * s.spacing : s.w * i / s.nx; };
  auto v_of = [&](int j) { return s.spacing > 0 ? j * s.spacing : s.h * j / s.ny; };
  g.UV.resize(cols * rows, 2);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) g.UV.row(j * cols + i) << u_of(i), v_of(j);
  g.V.resize(vcols * rows, 3);
  const double radius = s.bend > 0 ? s.w / s.bend : 0;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < vcols; ++i) {
      const double u = u_of(i), v = v_of(j);
      if (s.bend > 0) {
        const double a = u / radius;
        g.V.row(j * vcols + i) << radius * std::sin(a), v, radius * (1 - std::cos(a));
      } else if (s.plane_xz) {
        g.V.row(j * vcols + i) << u, s.offset, v;
      } else {
        g.V.row(j * vcols + i) << u, v, 0.0;
      }
    }
  g.uv_to_vertex.resize(cols * rows);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) g.uv_to_vertex[j * cols + i] = j * vcols + (s.wrap && i == s.nx ? 0 : i);
  if (s.layer_id >= 0) g.layer.assign(vcols * rows, s.layer_id);
  g.FUV.resize(2 * s.nx * s.ny, 3);
  int f = 0;
  for (int j = 0; j < s.ny; ++j)
    for (int i = 0; i < s.nx; ++i) {
      const int a = j * cols + i, b = a + 1, c = a + cols, d = c + 1;
      const bool rising = s.diagonals == GridSpec::Diagonals::Rising ||
                          (s.diagonals == GridSpec::Diagonals::Alternating && (i + j) % 2 == 0);
      if (s.diagonals == GridSpec::Diagonals::Falling) {  // diagonal b-c, wound to face +y in x-z
        g.FUV.row(f++) << a, c, b;
        g.FUV.row(f++) << b, c, d;
      } else if (rising) {
        g.FUV.row(f++) << a, b, d;
        g.FUV.row(f++) << a, d, c;
      } else {
        g.FUV.row(f++) << a, b, c;
        g.FUV.row(f++) << b, d, c;
      }
    }
  g.F.resize(g.FUV.rows(), 3);
  for (int t = 0; t < g.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) g.F(t, k) = g.uv_to_vertex[g.FUV(t, k)];
  return g;
}

}  // namespace gdsr_test

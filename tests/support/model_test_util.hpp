// Small synthetic garments and frames for the model tests (metres).
#pragma once

#include "gdsr/model/features.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "tests/support/grid_garment.hpp"
#include "nn/rng.hpp"

#include <cmath>

namespace gdsr_test {

// Two grids stacked `gap` apart in y: layer 0 below, layer 1 above.
inline gdsr::GarmentMesh two_layer_garment(int n, double size, double gap) {
  gdsr::GarmentMesh a = grid_garment(GridSpec::square(n, size)),
                    b = grid_garment(GridSpec::square(n, size).xz(gap).layer(1));
  gdsr::GarmentMesh g;
  const int V = n * n;
  g.V.resize(2 * V, 3);
  g.V << a.V, b.V;
  g.UV.resize(2 * V, 2);
  g.UV << a.UV, b.UV.array() + 2.0 * size;  // patterns side by side
  g.F.resize(2 * a.F.rows(), 3);
  g.F << a.F, (b.F.array() + V).matrix();
  g.FUV = g.F;
  for (int v = 0; v < 2 * V; ++v) g.uv_to_vertex.push_back(v), g.layer.push_back(v < V ? 0 : 1);
  return g;
}

// A frame around rest positions P: smooth motion plus small random perturbations.
inline gdsr::FrameInput make_frame(const gdsr::Points3& P, nn::Rng& rng, double amp = 0.004) {
  gdsr::FrameInput in;
  auto jitter = [&](const gdsr::Points3& X, double a) {
    gdsr::Points3 Y = X;
    for (int i = 0; i < Y.rows(); ++i)
      for (int k = 0; k < 3; ++k) Y(i, k) += rng.uniform(-a, a);
    return Y;
  };
  in.C_t = jitter(P, amp);
  in.C_tm1 = jitter(in.C_t, amp);
  in.C_tm2 = jitter(in.C_tm1, amp);
  in.Chat_tm1 = jitter(in.C_tm1, amp);
  in.Chat_tm2 = jitter(in.C_tm2, amp);
  return in;
}

// Random HR samples: n samples in random faces with random barycentrics.
inline gdsr::HrRequest random_samples(int num_faces, int n, nn::Rng& rng) {
  gdsr::HrRequest r;
  r.bary.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    r.tri.push_back(static_cast<int>(rng.below(static_cast<uint64_t>(num_faces))));
    double u = rng.uniform(0, 1), v = rng.uniform(0, 1);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    r.bary.row(i) << 1 - u - v, u, v;
  }
  return r;
}

// A square plane body (two triangles, normal +y) at height y, half-size h.
inline gdsr::TriMesh plane_body(double y, double h = 10.0) {
  gdsr::TriMesh b;
  b.V.resize(4, 3);
  b.V << -h, y, -h, h, y, -h, h, y, h, -h, y, h;
  b.F.resize(2, 3);
  b.F << 0, 2, 1, 0, 3, 2;  // counter-clockwise seen from +y
  return b;
}

}  // namespace gdsr_test

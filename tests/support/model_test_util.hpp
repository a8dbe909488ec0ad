// Small synthetic garments and frames for the model tests (metres).
#pragma once

#include "gdsr/model/features.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "tests/support/grid_garment.hpp"
#include "nn/rng.hpp"

#include <cmath>
#include <memory>
#include <string>

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

// The model in other length units: positions in the new unit are s x those in metres
// (s = 1e3: millimetres). The model reads and writes metres by design (features in metres feed
// H's MLPs, E and A output metres), so a change of units is a reparameterisation: every
// length in the config (sigma_b, sigma_l, noise_std) is multiplied by s, and so are the
// parameters that are lengths (unit_power 1: E's output scale and bias, A's field scale);
// the first-layer weights on metric inputs (node features 3..22, every edge feature) are
// divided by s (unit_power -1). Unit-free: normals, frames (frame_eps is relative), every
// hidden layer. Then C_hat(s C) = s C_hat(C) and G(s C) = s G(C) exactly, to rounding.
inline gdsr::ModelConfig config_in_units(gdsr::ModelConfig cfg, double s) {
  cfg.sigma_b *= s;
  cfg.sigma_l *= s;
  cfg.noise_std *= s;
  return cfg;
}

// The power p with which entry `col` (its column) of a parameter scales under a change of
// units (value x s^p).
inline int unit_power(const std::string& name, int64_t col) {
  if (name == "e.scale" || name == "e.bias" || name == "a.field_scale") return 1;
  if (name == "h.edge_enc.0.linear1.weight" || name == "h.layer_enc.0.linear1.weight") return -1;
  // weight [out x in]; of the node features only columns 0..2 (the normal) are unit-free
  if (name == "h.node_pre.0.linear1.weight") return col < 3 ? 0 : -1;
  return 0;
}

// `model` in metres -> a model in units s x metre (constructed from config_in_units(cfg, s)).
inline std::unique_ptr<gdsr::GDSR<double>> model_in_units(const gdsr::GDSR<double>& model, double s) {
  auto out = std::make_unique<gdsr::GDSR<double>>(config_in_units(model.config(), s));
  const auto src = model.named_parameters();
  auto dst = out->named_parameters();
  for (size_t i = 0; i < src.size(); ++i) {
    const ag::Storage<double>& v = src[i].second.values();
    ag::Storage<double>& d = dst[i].second.values();
    const int64_t cols = dst[i].second.cols();
    for (size_t j = 0; j < v.size(); ++j)
      d[j] = v[j] * std::pow(s, unit_power(src[i].first, static_cast<int64_t>(j) % cols));
  }
  return out;
}

// A frame in units s x metre (positions and body points scaled, body normals unit-free).
inline gdsr::FrameInput frame_in_units(gdsr::FrameInput in, double s) {
  for (gdsr::Points3* P :
       {&in.C_t, &in.C_tm1, &in.C_tm2, &in.Chat_tm1, &in.Chat_tm2, &in.contact_t.point, &in.contact_tm1.point})
    *P *= s;
  return in;
}

}  // namespace gdsr_test

#include "gdsr/model/gdsr_model.hpp"

#include "gdsr/error.hpp"

#include "autograd/autograd.hpp"
#include "gdsr/model/frames.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

namespace gdsr {

HrRequest hr_request_all(const Correspondence& c) {
  HrRequest r;
  r.tri = c.hr_from_lr.tri;
  r.bary = c.hr_from_lr.bary;
  return r;
}

HrRequest hr_request_subset(const Correspondence& c, const std::vector<int>& hr_vertices) {
  HrRequest r;
  r.tri.reserve(hr_vertices.size());
  r.bary.resize(static_cast<int64_t>(hr_vertices.size()), 3);
  for (size_t i = 0; i < hr_vertices.size(); ++i) {
    const int v = hr_vertices[i];
    if (v < 0 || v >= c.hr_from_lr.size()) gdsr::fail("gdsr_model", "HR vertex " + std::to_string(v) + " out of range");
    r.tri.push_back(c.hr_from_lr.tri[v]);
    r.bary.row(static_cast<int64_t>(i)) = c.hr_from_lr.bary.row(v);
  }
  return r;
}

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

template <class T> GDSR<T>::GDSR(const ModelConfig& cfg) : cfg_(cfg) {
  cfg.validate();
  nn::Rng rng(cfg.seed);
  h_ = this->register_module("h", std::make_shared<MeshGraphNet<T>>(cfg, rng));
  e_ = this->register_module("e", std::make_shared<CorrectionDecoder<T>>(cfg, rng));
  a_ = this->register_module("a", std::make_shared<HyperNet<T>>(cfg, rng));
  if (cfg.e_carry) carry = this->register_parameter("carry", ag::Tensor<T>::zeros({1, 1}));
}

template <class T> GdsrOutput<T> GDSR<T>::forward(const GarmentGraph& g, const FrameInput& in, const HrRequest* hr,
                                                  nn::Rng* noise, GdsrTimings* timings,
                                                  const HistoryTensors<T>* history) const {
  return forward(g, to_tensor<T>(in.C_t), in, hr, noise, timings, history);
}

template <class T> GdsrOutput<T> GDSR<T>::forward(const GarmentGraph& g, const ag::Tensor<T>& C_t, const FrameInput& in,
                                                  const HrRequest* hr, nn::Rng* noise, GdsrTimings* timings,
                                                  const HistoryTensors<T>* history) const {
  auto t0 = Clock::now();
  GraphFeatures<T> f = compute_features(g, C_t, in, cfg_, noise, history);
  if (timings) timings->features += since(t0);
  t0 = Clock::now();
  const ag::Tensor<T> z = h_->forward(g, f);
  if (timings) timings->h += since(t0);
  ag::Tensor<T> d_prev;  // the previous correction, for the carry only
  if (cfg_.e_carry)
    d_prev =
        history ? ag::sub(history->Chat_tm1, to_tensor<T>(in.C_tm1)) : to_tensor<T>(Points3(in.Chat_tm1 - in.C_tm1));
  GdsrOutput<T> out = decode(g, C_t, z, hr, timings, cfg_.e_carry ? &d_prev : nullptr);
  out.features = std::move(f);
  return out;
}

template <class T> GdsrOutput<T> GDSR<T>::decode(const GarmentGraph& g, const ag::Tensor<T>& C_t,
                                                 const ag::Tensor<T>& z, const HrRequest* hr, GdsrTimings* timings,
                                                 const ag::Tensor<T>* d_prev) const {
  const int64_t V = g.num_vertices, zd = cfg_.z_detail;
  if (C_t.rows() != V || C_t.cols() != 3)
    gdsr::fail("gdsr_model", "C must be [V x 3], got " + ag::shape_str(C_t.shape()));
  if (z.rows() != V || z.cols() != cfg_.decoder.back())
    gdsr::fail("gdsr_model",
               "z must be [V x " + std::to_string(cfg_.decoder.back()) + "], got " + ag::shape_str(z.shape()));
  GdsrOutput<T> out;
  out.C = C_t;
  out.z = z;
  auto t0 = Clock::now();
  if (ablation_.correction) {
    out.D = e_->forward(g, ag::slice_cols(z, zd, z.cols()), C_t);
    if (cfg_.e_carry && d_prev) {
      if (d_prev->rows() != V || d_prev->cols() != 3)
        gdsr::fail("gdsr_model", "the previous correction must be [V x 3], got " + ag::shape_str(d_prev->shape()));
      out.D = ag::add(out.D, ag::mul(*d_prev, carry));  // [V x 3] * [1 x 1] broadcasts
    }
    out.C_hat = ag::add(C_t, out.D);
  } else {
    out.D = ag::Tensor<T>::zeros({V, 3});
    out.C_hat = C_t;
  }
  if (timings) timings->e += since(t0);
  if (!hr || hr->size() == 0) return out;

  const int N = hr->size();
  if (hr->bary.rows() != N) gdsr::fail("gdsr_model", "HR request has mismatched tri/bary sizes");
  // The triangles A runs on: each needed triangle once.
  std::vector<int64_t> row_of(static_cast<size_t>(g.num_faces()), -1);
  for (int f : hr->tri) {
    if (f < 0 || f >= g.num_faces()) gdsr::fail("gdsr_model", "HR sample triangle out of range");
    row_of[f] = 0;
  }
  for (int f = 0; f < g.num_faces(); ++f)
    if (row_of[f] >= 0) row_of[f] = static_cast<int64_t>(out.faces.size()), out.faces.push_back(f);
  out.group.resize(N);
  for (int i = 0; i < N; ++i) out.group[i] = row_of[hr->tri[i]];
  // The field runs on the samples sorted by triangle (grouped_linear then works in place);
  // `order` is that permutation, `back` restores the request's order at the end.
  ag::Index order(N), back;
  for (int i = 0; i < N; ++i) order[i] = i;
  const bool sorted = std::is_sorted(out.group.begin(), out.group.end());
  if (!sorted) {
    std::stable_sort(order.begin(), order.end(), [&](int64_t a, int64_t b) { return out.group[a] < out.group[b]; });
    back.resize(N);
    for (int i = 0; i < N; ++i) back[order[i]] = i;
  }
  ag::Index group(N), corners(3 * static_cast<size_t>(N));
  ag::Tensor<T> bary = ag::Tensor<T>::zeros({N, 3});
  for (int i = 0; i < N; ++i) {
    const int64_t s = order[i];
    group[i] = out.group[s];
    for (int k = 0; k < 3; ++k) {
      corners[3 * i + k] = g.F(hr->tri[s], k);
      bary.data()[3 * i + k] = T(hr->bary(s, k));
    }
  }
  auto restore = [&](const ag::Tensor<T>& x) { return sorted ? x : ag::index_select_rows(x, back); };

  t0 = Clock::now();
  if (ablation_.detail) out.field = a_->parameters_for(g.F, out.faces, ag::slice_cols(z, 0, zd));
  if (timings) timings->a += since(t0);
  t0 = Clock::now();
  ag::Tensor<T> r_local, r_world;
  if (ablation_.detail) {
    r_local = a_->eval_field(out.field, bary, group);
    const ag::Tensor<T> frames = triangle_frames_ad(out.C_hat, g.F, out.faces, T(cfg_.frame_eps));
    r_world = local_to_world(r_local, ag::index_select_rows(frames, group));
  } else {
    r_local = r_world = ag::Tensor<T>::zeros({N, 3});
  }
  const ag::Tensor<T> up = ag::interpolate_rows(out.C_hat, corners, bary);
  const ag::Tensor<T> G = ag::add(up, r_world);
  out.residual_local = restore(r_local);
  out.residual = restore(r_world);
  out.upsampled = restore(up);
  out.G = restore(G);
  if (timings) timings->field += since(t0);
  return out;
}

template class GDSR<float>;
template class GDSR<double>;

}  // namespace gdsr

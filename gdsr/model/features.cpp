#include "gdsr/model/features.hpp"

#include "gdsr/error.hpp"

#include "autograd/autograd.hpp"
#include "gdsr/model/frames.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace gdsr {

namespace {

void check_rows(const char* what, const Points3& P, int V) {
  if (P.rows() != V)
    gdsr::fail("features", std::string(what) + " has " + std::to_string(P.rows()) + " rows, the garment has " +
                               std::to_string(V) + " vertices");
}

// [E x 9] edge features: x[dst] - x[src] and its length at t (differentiable in C_t), the
// same at t-1 (constant) and a constant last column (rest length or sigma_l).
template <class T> ag::Tensor<T> edge_features(const ag::Index& src, const ag::Index& dst, const ag::Tensor<T>& C_t,
                                               const Points3& C_tm1, const std::vector<double>& last) {
  const int64_t E = static_cast<int64_t>(src.size());
  const ag::Tensor<T> dv = ag::sub(ag::index_select_rows(C_t, dst), ag::index_select_rows(C_t, src));
  const ag::Tensor<T> len = ag::norm_rows(dv);
  ag::Tensor<T> rest = ag::Tensor<T>::zeros({E, 5});
  auto m = rest.mat();
  for (int64_t e = 0; e < E; ++e) {
    const Vec3 d = (C_tm1.row(dst[e]) - C_tm1.row(src[e])).transpose();
    m(e, 0) = T(d.x()), m(e, 1) = T(d.y()), m(e, 2) = T(d.z());
    m(e, 3) = T(d.norm());
    m(e, 4) = T(last[e]);
  }
  return ag::concat_cols<T>({dv, len, rest});
}

}  // namespace

template <class T> ag::Tensor<T> layer_edge_features(const LayerEdges& le, const ag::Tensor<T>& C_t,
                                                     const Points3& C_tm1, double sigma_l) {
  return edge_features(le.src, le.dst, C_t, C_tm1, std::vector<double>(le.src.size(), sigma_l));
}

template <class T> GraphFeatures<T> compute_features(const GarmentGraph& g, const ag::Tensor<T>& C_t,
                                                     const FrameInput& in, const ModelConfig& cfg, nn::Rng* noise,
                                                     const HistoryTensors<T>* history) {
  const int V = g.num_vertices;
  if (C_t.dim() != 2 || C_t.rows() != V || C_t.cols() != 3)
    gdsr::fail("features", "C_t tensor must be [" + std::to_string(V) + " x 3], got " + ag::shape_str(C_t.shape()));
  check_rows("C_t", in.C_t, V);
  check_rows("C_tm1", in.C_tm1, V);
  check_rows("C_tm2", in.C_tm2, V);
  check_rows("Chat_tm1", in.Chat_tm1, V);
  check_rows("Chat_tm2", in.Chat_tm2, V);

  GraphFeatures<T> out;
  const ag::Tensor<T> n = vertex_normals_ad(C_t, g.F);
  const ag::Tensor<T> vel = ag::sub(C_t, to_tensor<T>(in.C_tm1));
  const ag::Tensor<T> acc = ag::sub(C_t, to_tensor<T>(Points3(2.0 * in.C_tm1 - in.C_tm2)));

  // Body interaction at t (differentiable in C_t, b and n_b held fixed) ...
  ag::Tensor<T> m_t, p_t;
  // ... and of C_{t-1} against the body at t (constant), plus the history (constant).
  ag::Tensor<T> rest = ag::Tensor<T>::zeros({V, 10});
  auto r = rest.mat();
  if (in.has_body) {
    check_rows("contact_t.point", in.contact_t.point, V);
    check_rows("contact_t.normal", in.contact_t.normal, V);
    check_rows("contact_tm1.point", in.contact_tm1.point, V);
    check_rows("contact_tm1.normal", in.contact_tm1.normal, V);
    const ag::Tensor<T> nb = to_tensor<T>(in.contact_t.normal);
    const ag::Tensor<T> dist = ag::dot_rows(ag::sub(C_t, to_tensor<T>(in.contact_t.point)), nb);
    m_t = ag::relu(ag::add_scalar(ag::neg(dist), T(cfg.sigma_b)));
    p_t = ag::mul(m_t, nb);
    for (int i = 0; i < V; ++i) {
      const Vec3 nb1 = in.contact_tm1.normal.row(i).transpose();
      const double d = (in.C_tm1.row(i) - in.contact_tm1.point.row(i)).dot(nb1.transpose());
      const double m = std::max(cfg.sigma_b - d, 0.0);
      r(i, 0) = T(m);
      for (int k = 0; k < 3; ++k) r(i, 1 + k) = T(m * nb1[k]);
    }
  } else {
    m_t = ag::Tensor<T>::zeros({V, 1});
    p_t = ag::Tensor<T>::zeros({V, 3});
  }
  const bool add_noise = noise != nullptr && cfg.noise_std > 0;
  // With history tensors, the noise drawn here is kept to add to their columns below.
  ag::Tensor<T> history_noise = history ? ag::Tensor<T>::zeros({V, 6}) : ag::Tensor<T>();
  for (int i = 0; i < V; ++i)
    for (int k = 0; k < 3; ++k) {
      double d = in.Chat_tm1(i, k) - in.C_tm1(i, k);
      double vh = in.Chat_tm1(i, k) - in.Chat_tm2(i, k);
      if (add_noise) {
        const double nd = noise->normal(0.0, cfg.noise_std), nv = noise->normal(0.0, cfg.noise_std);
        d += nd, vh += nv;
        if (history) history_noise.mat()(i, k) = T(nd), history_noise.mat()(i, 3 + k) = T(nv);
      }
      r(i, 4 + k) = T(d);
      r(i, 7 + k) = T(vh);
    }
  if (history) {  // the same columns, differentiable in the history tensors
    const auto shape_ok = [V](const ag::Tensor<T>& X) { return X.dim() == 2 && X.rows() == V && X.cols() == 3; };
    if (!shape_ok(history->Chat_tm1) || !shape_ok(history->Chat_tm2))
      gdsr::fail("features", "history tensors must be [" + std::to_string(V) + " x 3], got " +
                                 ag::shape_str(history->Chat_tm1.shape()) + " and " +
                                 ag::shape_str(history->Chat_tm2.shape()));
    const ag::Tensor<T> d = ag::sub(history->Chat_tm1, to_tensor<T>(in.C_tm1));
    const ag::Tensor<T> vh = ag::sub(history->Chat_tm1, history->Chat_tm2);
    rest = ag::concat_cols<T>({ag::slice_cols(rest, 0, 4), ag::add(ag::concat_cols<T>({d, vh}), history_noise)});
  }
  if (cfg.node_length_unit != 1.0) {
    const T s = T(1.0 / cfg.node_length_unit);
    out.node = ag::concat_cols<T>({n, ag::mul_scalar(vel, s), ag::mul_scalar(acc, s), ag::mul_scalar(m_t, s),
                                   ag::mul_scalar(p_t, s), ag::mul_scalar(rest, s)});
  } else {
    out.node = ag::concat_cols<T>({n, vel, acc, m_t, p_t, rest});
  }

  out.ring1 = edge_features(g.ring1_src, g.ring1_dst, C_t, in.C_tm1, g.ring1_rest);
  out.layer_edges = find_layer_edges(g, in.C_t, cfg.sigma_l);
  if (out.layer_edges.size() > 0) out.layer = layer_edge_features(out.layer_edges, C_t, in.C_tm1, cfg.sigma_l);
  return out;
}

#define INSTANTIATE(T)                                                                                        \
  template GraphFeatures<T> compute_features<T>(const GarmentGraph&, const ag::Tensor<T>&, const FrameInput&, \
                                                const ModelConfig&, nn::Rng*, const HistoryTensors<T>*);      \
  template ag::Tensor<T> layer_edge_features<T>(const LayerEdges&, const ag::Tensor<T>&, const Points3&, double);
INSTANTIATE(float)
INSTANTIATE(double)
#undef INSTANTIATE

}  // namespace gdsr

#include "gdsr/model/model_h.hpp"

#include "gdsr/error.hpp"

#include "autograd/autograd.hpp"

#include <stdexcept>
#include <string>

namespace gdsr {

template <class T> MeshGraphNet<T>::MeshGraphNet(const ModelConfig& cfg, nn::Rng& rng) : cfg_(cfg) {
  cfg.validate();
  const bool norm = cfg.h_norm;
  const int64_t L = cfg.latent();
  const int64_t mid = cfg.node_encoder_pre.back();
  node_pre_ =
      this->register_module("node_pre", std::make_shared<nn::MLPStack<T>>(cfg.node_encoder_pre, norm, false, rng));
  node_mid_ = this->register_module("node_mid", std::make_shared<nn::Linear<T>>(mid, mid, true, rng));
  node_post_ =
      this->register_module("node_post", std::make_shared<nn::MLPStack<T>>(cfg.node_encoder_post, norm, false, rng));
  edge_enc_ = this->register_module("edge_enc", std::make_shared<nn::MLPStack<T>>(cfg.edge_encoder, norm, false, rng));
  if (cfg.layer_edge_mlps)
    layer_enc_ =
        this->register_module("layer_enc", std::make_shared<nn::MLPStack<T>>(cfg.edge_encoder, norm, false, rng));
  const int64_t node_in = (cfg.layer_edge_mlps ? 4 : 3) * L;
  for (int s = 0; s < cfg.mp_steps; ++s) {
    Step st;
    const std::string p = "step" + std::to_string(s) + "_";
    st.ring1 = this->register_module(p + "ring1", std::make_shared<nn::MLPBlock<T>>(3 * L, L, norm, false, rng));
    st.ring2 = this->register_module(p + "ring2", std::make_shared<nn::MLPBlock<T>>(3 * L, L, norm, false, rng));
    if (cfg.layer_edge_mlps)
      st.layer = this->register_module(p + "layer", std::make_shared<nn::MLPBlock<T>>(3 * L, L, norm, false, rng));
    st.node = this->register_module(p + "node", std::make_shared<nn::MLPBlock<T>>(node_in, L, norm, true, rng));
    steps_.push_back(st);
  }
  decoder_ = this->register_module("decoder", std::make_shared<nn::MLPStack<T>>(cfg.decoder, norm, false, rng));
}

namespace {
// e + mlp([x_src, x_dst, e]). The first linear map W [L x 3L] is applied by input block:
// (x W_src^T)[src] + (x W_dst^T)[dst] + e W_e^T + b, so the two vertex blocks cost a GEMM
// on the V vertices, gathered to the E edges, instead of one on every edge's copy of them
// (E is ~16 V on a triangle grid: the edge MLPs' multiply-adds halve). Equal to the concatenated
// form up to rounding.
template <class T> ag::Tensor<T> edge_update(const nn::MLPBlock<T>& mlp, const ag::Tensor<T>& x, const ag::Tensor<T>& e,
                                             const ag::Index& src, const ag::Index& dst) {
  const int64_t L = x.cols();
  const ag::Tensor<T>& W = mlp.linear1->weight;
  const ag::Tensor<T> xs = ag::linear(x, ag::slice_cols(W, 0, L), ag::Tensor<T>());
  const ag::Tensor<T> xd = ag::linear(x, ag::slice_cols(W, L, 2 * L), ag::Tensor<T>());
  ag::Tensor<T> pre = ag::linear(e, ag::slice_cols(W, 2 * L, 3 * L), mlp.linear1->bias);
  pre = ag::add_gathered_rows(pre, xs, src, xd, dst);  // pre + (xs[src] + xd[dst])
  return ag::add(e, mlp.after_first(ag::leaky_relu(pre, static_cast<T>(nn::MLPBlock<T>::kSlope))));
}
}  // namespace

template <class T> ag::Tensor<T> MeshGraphNet<T>::forward(const GarmentGraph& g, const GraphFeatures<T>& f) const {
  const int64_t V = g.num_vertices, L = cfg_.latent();
  if (f.node.rows() != V || f.node.cols() != kNodeFeatures)
    gdsr::fail("model_h", "node features must be [V x " + std::to_string(kNodeFeatures) + "], got " +
                              ag::shape_str(f.node.shape()));
  if (f.ring1.rows() != g.ring1_size() || f.ring1.cols() != kEdgeFeatures)
    gdsr::fail("model_h", "ring-1 features must be [E1 x " + std::to_string(kEdgeFeatures) + "], got " +
                              ag::shape_str(f.ring1.shape()));

  ag::Tensor<T> x = node_post_->forward(ag::channel_norm(node_mid_->forward(node_pre_->forward(f.node))));
  ag::Tensor<T> e1 = edge_enc_->forward(f.ring1);
  ag::Tensor<T> e2 = ag::Tensor<T>::zeros({g.ring2_size(), L});
  const bool use_layer = cfg_.layer_edge_mlps && f.layer_edges.size() > 0;
  ag::Tensor<T> el;
  if (use_layer) el = layer_enc_->forward(f.layer);

  const ag::Tensor<T> zero_agg = ag::Tensor<T>::zeros({V, L});
  for (const Step& st : steps_) {
    e1 = edge_update(*st.ring1, x, e1, g.ring1_src, g.ring1_dst);
    std::vector<ag::Tensor<T>> parts{x, ag::scatter_add_rows(e1, g.ring1_src, V)};
    if (g.ring2_size() > 0) {
      e2 = edge_update(*st.ring2, x, e2, g.ring2_src, g.ring2_dst);
      parts.push_back(ag::scatter_add_rows(e2, g.ring2_src, V));
    } else {
      parts.push_back(zero_agg);
    }
    if (cfg_.layer_edge_mlps) {
      if (use_layer) {
        el = edge_update(*st.layer, x, el, f.layer_edges.src, f.layer_edges.dst);
        parts.push_back(ag::scatter_add_rows(el, f.layer_edges.src, V));
      } else {
        parts.push_back(zero_agg);
      }
    }
    x = ag::add(x, st.node->forward(ag::concat_cols<T>(parts)));
  }
  return decoder_->forward(x);
}

template class MeshGraphNet<float>;
template class MeshGraphNet<double>;

}  // namespace gdsr

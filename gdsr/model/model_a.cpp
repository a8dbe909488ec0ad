#include "gdsr/model/model_a.hpp"

#include "gdsr/error.hpp"

#include "autograd/autograd.hpp"
#include "gdsr/model/model_e.hpp"

#include <algorithm>
#include <complex>
#include <stdexcept>

namespace gdsr {

template <class T> HyperNet<T>::HyperNet(const ModelConfig& cfg, nn::Rng& rng) : cfg_(cfg) {
  cfg.validate();
  const int64_t P = cfg.field_params();
  mlp_ = this->register_module("mlp", std::make_shared<nn::MLPStack<T>>(cfg.a_widths, false, false, rng));
  proj_re_ = this->register_module("proj_re", std::make_shared<nn::Linear<T>>(cfg.a_widths.back(), P, false, rng));
  proj_im_ = this->register_module("proj_im", std::make_shared<nn::Linear<T>>(cfg.a_widths.back(), P, false, rng));
  if (cfg.a_proj_init_gain != 1.0) {
    for (T& w : proj_re_->weight.values()) w *= T(cfg.a_proj_init_gain);
    for (T& w : proj_im_->weight.values()) w *= T(cfg.a_proj_init_gain);
  }
  ag::Tensor<T> s = ag::Tensor<T>::zeros({1, 3});
  for (int k = 0; k < 3; ++k) s.data()[k] = T(cfg.field_scale_init * rng.normal(0.0, 1.0));
  field_scale = this->register_parameter("field_scale", s);
}

template <class T>
FieldParams<T> HyperNet<T>::parameters_for(const Faces& F, const ag::Index& faces, const ag::Tensor<T>& z) const {
  const int64_t C = z.cols();
  if (3 * C != cfg_.a_widths.front())
    gdsr::fail("model_a", "z_detail must have " + std::to_string(cfg_.a_widths.front() / 3) + " columns, got " +
                              ag::shape_str(z.shape()));
  const nn::MLPBlock<T>& first = *mlp_->blocks.front();
  ag::Tensor<T> h;
  if (static_cast<int64_t>(faces.size()) > z.rows()) {
    // More triangles than vertices (a whole frame has ~2 per vertex): the first linear map
    // per corner block on z's V rows, gathered to the triangles, rather than on three copies
    // of every vertex's row. Equal up to rounding.
    const ag::Tensor<T>& W = first.linear1->weight;
    ag::Tensor<T> pre;
    for (int k = 0; k < 3; ++k) {
      ag::Index corner(faces.size());
      for (size_t i = 0; i < faces.size(); ++i) corner[i] = F(faces[i], k);
      const ag::Tensor<T> zk =
          ag::linear(z, ag::slice_cols(W, k * C, (k + 1) * C), k == 0 ? first.linear1->bias : ag::Tensor<T>());
      const ag::Tensor<T> g = ag::index_select_rows(zk, corner);
      pre = k == 0 ? g : ag::add(pre, g);
    }
    h = first.after_first(ag::leaky_relu(pre, static_cast<T>(nn::MLPBlock<T>::kSlope)));
  } else {
    h = first.forward(gather_face_features(F, faces, z));
  }
  for (size_t b = 1; b < mlp_->blocks.size(); ++b) h = mlp_->blocks[b]->forward(h);
  return {proj_re_->forward(h), proj_im_->forward(h)};
}

template <class T> ag::Tensor<T> HyperNet<T>::eval_field(const FieldParams<T>& p, const ag::Tensor<T>& bary,
                                                         const ag::Index& group) const {
  using C = std::complex<T>;
  if (bary.cols() != 3 || bary.rows() != static_cast<int64_t>(group.size()))
    gdsr::fail("model_a", "bary must be [N x 3] with one group per row");
  const auto layers = cfg_.field_layers();
  const T omega0 = T(cfg_.wire_omega0), s0 = T(cfg_.wire_s0);
  auto block_re = [&](int64_t b, int64_t n) { return ag::slice_cols(p.re, b, b + n); };
  auto block_c = [&](int64_t b, int64_t n) {
    return ag::complex_from(ag::slice_cols(p.re, b, b + n), ag::slice_cols(p.im, b, b + n));
  };
  // Layer 0 is real (only the real parts of its parameters are used).
  const auto& l0 = layers.front();
  ag::Tensor<T> h0 =
      ag::grouped_linear(bary, block_re(l0.w_begin, l0.in * l0.out), block_re(l0.b_begin, l0.out), group, l0.out);
  ag::Tensor<C> h = ag::wire(ag::complex_from_real(h0), omega0, s0);
  // Rows sorted by group (as GDSR::decode passes them): the complex layers read their weights
  // in place from p.re / p.im, without slicing and interleaving copies of them.
  const bool sorted = std::is_sorted(group.begin(), group.end());
  for (size_t l = 1; l < layers.size(); ++l) {
    const auto& L = layers[l];
    h = sorted ? ag::grouped_linear_planes(h, p.re, p.im, L.w_begin, L.b_begin, group, L.out)
               : ag::grouped_linear(h, block_c(L.w_begin, L.in * L.out), block_c(L.b_begin, L.out), group, L.out);
    if (l + 1 < layers.size()) h = ag::wire(h, omega0, s0);
  }
  return ag::mul(ag::tanh(ag::real(h)), field_scale);
}

template class HyperNet<float>;
template class HyperNet<double>;

}  // namespace gdsr

#include "gdsr/model/model_e.hpp"

#include "gdsr/error.hpp"

#include "autograd/autograd.hpp"
#include "gdsr/model/frames.hpp"

#include <stdexcept>

namespace gdsr {

template <class T> ag::Tensor<T> gather_face_features(const Faces& F, const ag::Index& faces, const ag::Tensor<T>& z) {
  std::vector<ag::Tensor<T>> parts;
  for (int k = 0; k < 3; ++k) {
    ag::Index idx(faces.size());
    for (size_t i = 0; i < faces.size(); ++i) idx[i] = F(faces[i], k);
    parts.push_back(ag::index_select_rows(z, idx));
  }
  return ag::concat_cols<T>(parts);
}

template <class T> CorrectionDecoder<T>::CorrectionDecoder(const ModelConfig& cfg, nn::Rng& rng) : cfg_(cfg) {
  cfg.validate();
  mlp_ = this->register_module("mlp", std::make_shared<nn::MLPStack<T>>(cfg.e_widths, false, false, rng));
  out_ = this->register_module("out", std::make_shared<nn::Linear<T>>(cfg.e_widths.back(), 9, true, rng));
  ag::Tensor<T> s = ag::Tensor<T>::zeros({1, 3});
  for (int k = 0; k < 3; ++k) s.data()[k] = T(cfg.e_scale_init * rng.normal(0.0, 1.0));
  scale = this->register_parameter("scale", s);
  bias = this->register_parameter("bias", ag::Tensor<T>::zeros({1, 3}));
}

template <class T>
ag::Tensor<T> CorrectionDecoder<T>::local_displacements(const GarmentGraph& g, const ag::Tensor<T>& z) const {
  if (z.rows() != g.num_vertices || z.cols() != cfg_.z_disp())
    gdsr::fail("model_e",
               "z_disp must be [V x " + std::to_string(cfg_.z_disp()) + "], got " + ag::shape_str(z.shape()));
  ag::Index all(g.num_faces());
  for (int f = 0; f < g.num_faces(); ++f) all[f] = f;
  const ag::Tensor<T> h = out_->forward(mlp_->forward(gather_face_features(g.F, all, z)));  // F x 9
  const ag::Tensor<T> d = ag::reshape(h, {3 * static_cast<int64_t>(g.num_faces()), 3});
  return ag::add(ag::mul(ag::tanh(d), scale), bias);
}

template <class T> ag::Tensor<T> CorrectionDecoder<T>::to_vertex_displacements(const GarmentGraph& g,
                                                                               const ag::Tensor<T>& local,
                                                                               const ag::Tensor<T>& C) const {
  ag::Index all(g.num_faces()), corner_face(3 * g.num_faces());
  for (int f = 0; f < g.num_faces(); ++f) {
    all[f] = f;
    for (int k = 0; k < 3; ++k) corner_face[3 * f + k] = f;
  }
  const ag::Tensor<T> frames = triangle_frames_ad(C, g.F, all, T(cfg_.frame_eps));
  const ag::Tensor<T> world = local_to_world(local, ag::index_select_rows(frames, corner_face));
  return ag::scatter_mean_rows(world, g.face_corners, g.num_vertices);
}

template class CorrectionDecoder<float>;
template class CorrectionDecoder<double>;
template ag::Tensor<float> gather_face_features<float>(const Faces&, const ag::Index&, const ag::Tensor<float>&);
template ag::Tensor<double> gather_face_features<double>(const Faces&, const ag::Index&, const ag::Tensor<double>&);

}  // namespace gdsr

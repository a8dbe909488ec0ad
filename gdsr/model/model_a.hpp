// Hyper-net A and the per-triangle WIRE field (paper 4.4, reference-facts "Hyper-net A"):
// per LR triangle, P complex field parameters from the three vertices' z_detail; the field
// maps barycentric coordinates (1-u-v, u, v) of HR samples to a residual in the triangle's
// local frame. A runs once per needed triangle, the field once per HR sample, with
// grouped_linear (each sample uses its triangle's parameters).
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "gdsr/model/model_config.hpp"
#include "nn/linear.hpp"
#include "nn/mlp.hpp"

#include <memory>

namespace gdsr {

template <class T> struct FieldParams {
  ag::Tensor<T> re, im;  // [F_needed x P] real and imaginary parts, layout ModelConfig::field_layers
};

template <class T> class HyperNet : public nn::Module<T> {
 public:
  HyperNet(const ModelConfig& cfg, nn::Rng& rng);

  // Field parameters [faces.size() x P] of the triangles `faces` of F from z_detail [V x C]
  // (A's input per triangle: its three corners' rows, concatenated: gather_face_features).
  FieldParams<T> parameters_for(const Faces& F, const ag::Index& faces, const ag::Tensor<T>& z_detail) const;

  // bary [N x 3] (constant), group: N indices into the rows of p -> local residual
  // [N x 3] = tanh(Re(field(bary))) * field_scale.
  ag::Tensor<T> eval_field(const FieldParams<T>& p, const ag::Tensor<T>& bary, const ag::Index& group) const;

  ag::Tensor<T> field_scale;  // [1 x 3]

 private:
  ModelConfig cfg_;
  std::shared_ptr<nn::MLPStack<T>> mlp_;
  std::shared_ptr<nn::Linear<T>> proj_re_, proj_im_;
};

}  // namespace gdsr

// Correction decoder E (paper 4.3, reference-facts "Correction decoder E"): per LR triangle
// three displacements in the triangle's local frame of C, mapped to world and averaged per
// vertex: D [V x 3] (metres), C_hat = C + D.
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/model/graph.hpp"
#include "gdsr/model/model_config.hpp"
#include "nn/linear.hpp"
#include "nn/mlp.hpp"

#include <memory>

namespace gdsr {

template <class T> class CorrectionDecoder : public nn::Module<T> {
 public:
  CorrectionDecoder(const ModelConfig& cfg, nn::Rng& rng);

  // Local displacements per face corner [3F x 3] (row 3f+k: corner k of face f) from
  // z_disp [V x z_disp]: MLP blocks, Linear -> 9, tanh, * scale + bias (per axis).
  ag::Tensor<T> local_displacements(const GarmentGraph& g, const ag::Tensor<T>& z_disp) const;
  // Local displacements -> world with the frames of C [V x 3], averaged per vertex -> D [V x 3].
  ag::Tensor<T> to_vertex_displacements(const GarmentGraph& g, const ag::Tensor<T>& local,
                                        const ag::Tensor<T>& C) const;
  ag::Tensor<T> forward(const GarmentGraph& g, const ag::Tensor<T>& z_disp, const ag::Tensor<T>& C) const {
    return to_vertex_displacements(g, local_displacements(g, z_disp), C);
  }

  ag::Tensor<T> scale, bias;  // [1 x 3] each

 private:
  ModelConfig cfg_;
  std::shared_ptr<nn::MLPStack<T>> mlp_;
  std::shared_ptr<nn::Linear<T>> out_;
};

// concat of the three corner rows of z per face [F x 3C] (faces `faces` of g.F).
template <class T> ag::Tensor<T> gather_face_features(const Faces& F, const ag::Index& faces, const ag::Tensor<T>& z);

}  // namespace gdsr

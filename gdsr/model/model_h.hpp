// Mesh-Graph-Net H (paper 4.2, reference-facts "Mesh-Graph-Net H"): node / edge encoders,
// mp_steps message-passing steps over ring-1, ring-2 and (optional) layer edges with
// residual updates, and the decoder to z = [z_detail | z_disp] per LR vertex.
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/model/features.hpp"
#include "gdsr/model/graph.hpp"
#include "gdsr/model/model_config.hpp"
#include "nn/linear.hpp"
#include "nn/mlp.hpp"

#include <memory>
#include <vector>

namespace gdsr {

template <class T> class MeshGraphNet : public nn::Module<T> {
 public:
  MeshGraphNet(const ModelConfig& cfg, nn::Rng& rng);

  // Features of one frame -> z [V x decoder.back()]; columns [0, z_detail) feed A, the
  // rest feed E. Layer edges take part only when present in `f` (and cfg.layer_edge_mlps).
  ag::Tensor<T> forward(const GarmentGraph& g, const GraphFeatures<T>& f) const;

  struct Step {
    std::shared_ptr<nn::MLPBlock<T>> ring1, ring2, layer, node;  // layer null when disabled
  };

 private:
  ModelConfig cfg_;
  std::shared_ptr<nn::MLPStack<T>> node_pre_, node_post_, edge_enc_, layer_enc_, decoder_;
  std::shared_ptr<nn::Linear<T>> node_mid_;
  std::vector<Step> steps_;
};

}  // namespace gdsr

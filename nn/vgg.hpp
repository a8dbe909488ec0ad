// Frozen VGG19 feature extractor for perceptual losses: conv3x3 + ReLU, every max pool
// replaced by a 2x2 average pool (as in the GDSR reference). Weights never receive
// gradients; gradients flow to the input image.
#pragma once

#include "autograd/tensor.hpp"
#include "nn/vgg_weights.hpp"

#include <string>
#include <vector>

namespace nn {

template <class T> class VGG19Features {
 public:
  // layers: ReLU outputs to return ("relu1_1" ... "relu5_4"); empty = every one of relu1_2,
  // relu2_1, relu3_1, relu4_1, relu5_1 that the loaded weights reach (relu1_2, relu2_1,
  // relu3_1 with the shared blocks 1-3). Throws if a requested layer needs missing weights.
  explicit VGG19Features(const VggWeights& weights, std::vector<std::string> layers = {});
  // Loads the Keras/TF.js directory (see load_vgg19_keras).
  explicit VGG19Features(const std::string& keras_dir = vgg19_default_dir(), std::vector<std::string> layers = {});

  // image [N x 3 x H x W], RGB in 0..1 (H, W multiples of 2^(pools before the deepest
  // layer) avoid dropped border rows) -> one tensor per layer, [N x C_l x H_l x W_l], in
  // the order of layer_names(). The preprocessing that matches the weights is applied
  // inside (folded exactly into the first convolution and an input shift).
  std::vector<ag::Tensor<T>> features(const ag::Tensor<T>& image) const;

  const std::vector<std::string>& layer_names() const { return layers_; }
  int64_t num_convs() const { return static_cast<int64_t>(w_.size()); }
  const VggWeights& source_weights() const { return src_; }

  // The default layer list for a net with num_convs convolutions.
  static std::vector<std::string> default_layers(int64_t num_convs);

 private:
  void build(std::vector<std::string> layers);

  VggWeights src_;
  std::vector<ag::Tensor<T>> w_, b_;  // per conv: [O x C x 3 x 3], [O]; w_[0] has preprocessing folded in
  T offset_[3];                       // per RGB channel, subtracted from the 0..1 input
  std::vector<std::string> layers_;
  std::vector<int> layer_conv_;  // conv index (0-based) whose ReLU output each layer is
};

}  // namespace nn

// Perceptual (VGG feature) losses between predicted and target images or feature maps.
#pragma once

#include "autograd/tensor.hpp"
#include "nn/vgg.hpp"

#include <vector>

namespace nn {

enum class FeatureLossKind {
  Cosine,  // per layer: 1 - mean over pixels of cos(pred, target) over channels (GDSR code default)
  L1,      // per layer: mean |pred - target| over all elements (the paper's text)
};

// a, b [N x C x H x W] -> [1 x 1]: 1 - mean over the N*H*W pixels of the cosine similarity
// of the C-vectors, cos = a.b / (max(|a|, eps) max(|b|, eps)) (torch.nn.functional.
// cosine_similarity). Gradients to a and b (either may be constant). Valid for all finite
// entries: each pixel's vectors are scaled by their largest |entry| first, so entries from
// subnormal to near the largest float give the exact cosine (a plain a.a overflows in float32
// beyond ~1e19). eps must be finite and > 0 (ag::Error otherwise), in the units of a and b.
template <class T>
ag::Tensor<T> cosine_distance_channels(const ag::Tensor<T>& a, const ag::Tensor<T>& b, T eps = T(1e-8));

// Sum over layers of the per-layer loss; pred and target hold matching feature maps.
template <class T> ag::Tensor<T> feature_loss(const std::vector<ag::Tensor<T>>& pred,
                                              const std::vector<ag::Tensor<T>>& target,
                                              FeatureLossKind kind = FeatureLossKind::Cosine);

// VGG loss of two images [N x 3 x H x W] (RGB 0..1). Target features are computed without a
// graph unless the target image requires grad.
template <class T> ag::Tensor<T> vgg_loss(const VGG19Features<T>& vgg, const ag::Tensor<T>& pred,
                                          const ag::Tensor<T>& target, FeatureLossKind kind = FeatureLossKind::Cosine);

}  // namespace nn

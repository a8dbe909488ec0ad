// Normalisations without affine parameters (apply scale/shift with mul/add).
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

// Per-channel normalisation across rows: each column of x [R x C] is shifted to mean 0 and
// scaled by 1/sqrt(var + eps) (biased variance). GroupNorm with one group per channel
// over all vertices/edges of a graph, as in the reference MLP block. Equal rows -> 0.
// Valid for any finite x (statistics are taken on x scaled by its largest magnitude, so
// float32 entries near 1e38 or subnormal ones give the exact O(1) result); eps must be
// finite and > 0 (ag::Error otherwise), in the squared units of x.
template <class T> Tensor<T> channel_norm(const Tensor<T>& x, T eps = T(1e-5));
// Per-row normalisation (LayerNorm without affine) over the columns of x [R x C]. Same
// range and eps rule as channel_norm.
template <class T> Tensor<T> layer_norm(const Tensor<T>& x, T eps = T(1e-5));

}  // namespace ag

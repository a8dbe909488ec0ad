// Image ops on N x C x H x W tensors (real scalars).
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

// 3x3 convolution (cross-correlation as in every DL framework), stride 1, zero padding 1.
// x [N x C x H x W], weight [O x C x 3 x 3], bias [O] (or [1 x O]) or undefined -> [N x O x H x W].
template <class T> Tensor<T> conv2d_3x3(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias);
// 2x2 pooling, stride 2 (H, W even or the last row/col dropped) -> [N x C x H/2 x W/2].
template <class T> Tensor<T> avg_pool2x2(const Tensor<T>& x);
template <class T> Tensor<T> max_pool2x2(const Tensor<T>& x);

}  // namespace ag

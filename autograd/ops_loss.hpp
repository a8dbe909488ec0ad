// Losses between a prediction and a target of the same shape, reduced by the mean over all
// elements -> [1 x 1]. The target may or may not require grad.
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

// mean |p - t|; gradient sign(p - t) / n, 0 where p = t. Both need n > 0 (ag::Error).
// Valid for any finite p, t whose mean is representable: where the sum of the terms would
// overflow it is taken on p, t scaled by a power of two. (mse: the gradient 2 (p - t) / n
// is inf only where p - t itself exceeds the largest float.)
template <class T> Tensor<T> l1_loss(const Tensor<T>& pred, const Tensor<T>& target);
template <class T> Tensor<T> mse_loss(const Tensor<T>& pred, const Tensor<T>& target);  // mean (p - t)^2

}  // namespace ag

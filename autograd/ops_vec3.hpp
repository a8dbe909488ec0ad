// Row-wise vector ops: each row of a [R x C] tensor is one vector (C = 3 for cross).
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

template <class T> Tensor<T> dot_rows(const Tensor<T>& a, const Tensor<T>& b);  // [R x C] -> [R x 1]
template <class T> Tensor<T> cross3(const Tensor<T>& a, const Tensor<T>& b);    // [R x 3] -> [R x 3]
// Euclidean norm per row -> [R x 1]. At a zero row the gradient is taken as 0 (subgradient).
template <class T> Tensor<T> norm_rows(const Tensor<T>& x);
// x / max(|x|, eps) per row (PyTorch's F.normalize): finite value and gradient at zero rows.
template <class T> Tensor<T> normalize_rows(const Tensor<T>& x, T eps = T(1e-12));

}  // namespace ag

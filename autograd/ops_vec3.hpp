// Row-wise vector ops: each row of a [R x C] tensor is one vector (C = 3 for cross).
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

template <class T> Tensor<T> dot_rows(const Tensor<T>& a, const Tensor<T>& b);  // [R x C] -> [R x 1]
template <class T> Tensor<T> cross3(const Tensor<T>& a, const Tensor<T>& b);    // [R x 3] -> [R x 3]
// Euclidean norm per row -> [R x 1]. At a zero row the gradient is taken as 0 (subgradient).
// Valid for any finite x: computed on the row scaled by its largest magnitude (as hypot), so
// the value is exact for subnormal rows and the gradient x / |x| stays a unit vector at any
// magnitude; the value is inf only where |x| itself exceeds the largest float.
template <class T> Tensor<T> norm_rows(const Tensor<T>& x);
// x / max(|x|, eps) per row (PyTorch's F.normalize): finite value and gradient at zero rows.
// eps must be finite and > 0 (ag::Error otherwise), in the units of x; rows longer than eps
// give the exact unit vector at any magnitude up to the largest float.
template <class T> Tensor<T> normalize_rows(const Tensor<T>& x, T eps = T(1e-12));

}  // namespace ag

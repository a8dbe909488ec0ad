// Matrix products through Eigen's GEMM. Shapes: a [M x K], b [K x N] -> [M x N].
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

template <class T> Tensor<T> matmul(const Tensor<T>& a, const Tensor<T>& b);
// x [N x in], weight [out x in] (PyTorch's layout), bias [1 x out] or undefined -> [N x out]:
// y = x W^T + b.
template <class T> Tensor<T> linear(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias);
template <class T> Tensor<T> transpose(const Tensor<T>& a);  // [M x N] -> [N x M]

}  // namespace ag

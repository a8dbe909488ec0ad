// Matrix products through Eigen's GEMM. Shapes: a [M x K], b [K x N] -> [M x N].
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

template <class T> Tensor<T> matmul(const Tensor<T>& a, const Tensor<T>& b);
// x [N x in], weight [out x in] (PyTorch's layout), bias [1 x out] or undefined -> [N x out]:
// y = x W^T + b.
template <class T> Tensor<T> linear(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias);
// leaky_relu(linear(x, weight, bias), slope) in one op (bias and activation applied in one
// pass over the GEMM's output, no intermediate tensor). Real scalars; slope > 0 (the
// derivative is read from the output's sign).
template <class T>
Tensor<T> linear_leaky_relu(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias, T slope);
template <class T> Tensor<T> transpose(const Tensor<T>& a);  // [M x N] -> [N x M]

}  // namespace ag

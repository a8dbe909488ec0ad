// Concatenation, slicing and reshaping of 2-D tensors [R x C] (reshape: any rank).
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

template <class T> Tensor<T> concat_cols(const std::vector<Tensor<T>>& xs);               // equal rows
template <class T> Tensor<T> concat_rows(const std::vector<Tensor<T>>& xs);               // equal cols
template <class T> Tensor<T> slice_cols(const Tensor<T>& x, int64_t begin, int64_t end);  // [R x (end-begin)]
template <class T> Tensor<T> slice_rows(const Tensor<T>& x, int64_t begin, int64_t end);  // [(end-begin) x C]
template <class T>
Tensor<T> reshape(const Tensor<T>& x, const Shape& shape);  // same element count, row-major order kept

}  // namespace ag

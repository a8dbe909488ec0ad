// Reductions over a 2-D tensor [R x C]. (sum and mean accept any rank.) The means need a
// non-empty extent (ag::Error on 0 elements, where the mean is undefined). A mean is the sum
// divided by the count: inf once that sum exceeds the largest float, even where the mean
// itself would not (entries near 1e308; the losses in ops_loss.hpp avoid this).
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

template <class T> Tensor<T> sum(const Tensor<T>& x);        // -> [1 x 1]
template <class T> Tensor<T> mean(const Tensor<T>& x);       // -> [1 x 1]
template <class T> Tensor<T> sum_rows(const Tensor<T>& x);   // per row, over columns -> [R x 1]
template <class T> Tensor<T> mean_rows(const Tensor<T>& x);  // -> [R x 1]
template <class T> Tensor<T> sum_cols(const Tensor<T>& x);   // per column, over rows -> [1 x C]
template <class T> Tensor<T> mean_cols(const Tensor<T>& x);  // -> [1 x C]

}  // namespace ag

// Gather and scatter of rows: the message-passing primitives.
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

// out[i] = x[index[i]]: x [R x C], index values in [0, R) -> [len(index) x C].
template <class T> Tensor<T> index_select_rows(const Tensor<T>& x, const Index& index);
// out[index[i]] += x[i]: x [N x C], index values in [0, num_rows) -> [num_rows x C]
// (segment sum; rows nobody points at stay 0).
template <class T> Tensor<T> scatter_add_rows(const Tensor<T>& x, const Index& index, int64_t num_rows);
// out[i] = base[i] + (a[ia[i]] + b[ib[i]]): base [N x C], a [Ra x C], b [Rb x C], N indices
// each -> [N x C]. A message-passing edge's input (its own projection plus its sender's and
// receiver's) in one pass, equal bit for bit to add(base, add(index_select_rows(a, ia),
// index_select_rows(b, ib))) without the three [N x C] temporaries, and in backward without
// their gradients: d base = g, d a = scatter_add_rows(g, ia), d b = scatter_add_rows(g, ib).
template <class T> Tensor<T> add_gathered_rows(const Tensor<T>& base, const Tensor<T>& a, const Index& ia,
                                               const Tensor<T>& b, const Index& ib);
// Like scatter_add_rows, divided by the number of contributions (0 rows stay 0).
template <class T> Tensor<T> scatter_mean_rows(const Tensor<T>& x, const Index& index, int64_t num_rows);
// out[i] = sum_k weight[i,k] * x[index[i,k]]: x [R x C], index [N x K] row-major (K per row),
// weight [N x K] tensor (differentiable too) -> [N x C]. Barycentric interpolation
// (K = 3) for upsampling and for drawing normal maps from a UV raster.
template <class T> Tensor<T> interpolate_rows(const Tensor<T>& x, const Index& index, const Tensor<T>& weight);

}  // namespace ag

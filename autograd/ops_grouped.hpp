// Grouped linear map: each row is multiplied by its own small weight matrix chosen by an
// index (the hyper-network's per-triangle fields: one weight set per LR triangle, applied to
// all HR samples inside that triangle). Real and complex scalars.
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

// x [N x in]; weight [G x (out*in)], row g holds matrix g as (out x in) row-major;
// bias [G x out] or undefined; group: N values in [0, G).
// out[n] = W[group[n]] x[n] + b[group[n]]  -> [N x out].
// Rows with the same group are processed together as one small GEMM.
template <class T> Tensor<T> grouped_linear(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias,
                                            const Index& group, int64_t out_features);

// The complex grouped map with its weights read in place from two real planes (the hyper-
// network's output, without slicing and interleaving copies): re, im [G x P]; group g's
// matrix is W[o][i] = re[g, w_begin + o*in + i] + i im[g, w_begin + o*in + i] and its bias
// b[o] = re[g, b_begin + o] + i im[g, b_begin + o] (b_begin < 0: none). x [N x in] complex,
// group non-decreasing (rows sorted by group). Equals grouped_linear(x, complex_from(
// slice_cols(re, ..), slice_cols(im, ..)), ...) up to rounding order -> [N x out].
template <class R> Tensor<std::complex<R>> grouped_linear_planes(const Tensor<std::complex<R>>& x, const Tensor<R>& re,
                                                                 const Tensor<R>& im, int64_t w_begin, int64_t b_begin,
                                                                 const Index& group, int64_t out_features);

}  // namespace ag

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
template <class T>
Tensor<T> grouped_linear(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias,
                         const Index& group, int64_t out_features);

}  // namespace ag

// Fully connected layer, PyTorch's nn.Linear: y = x W^T + b.
#pragma once

#include "nn/module.hpp"
#include "nn/rng.hpp"

namespace nn {

template <class T> class Linear : public Module<T> {
 public:
  // weight [out x in] ~ kaiming_uniform(a = sqrt(5)) = U(-1/sqrt(in), 1/sqrt(in));
  // bias [1 x out] ~ U(-1/sqrt(in), 1/sqrt(in)) (PyTorch's default). Names "weight", "bias".
  Linear(int64_t in, int64_t out, bool bias, Rng& rng);
  // x [N x in] -> [N x out].
  ag::Tensor<T> forward(const ag::Tensor<T>& x) const;
  int64_t in_features() const { return in_; }
  int64_t out_features() const { return out_; }

  ag::Tensor<T> weight, bias;  // bias undefined when bias = false

 private:
  int64_t in_, out_;
};

}  // namespace nn

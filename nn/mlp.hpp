// The reference implementation's "MLP block" and a chain of them.
#pragma once

#include "nn/linear.hpp"

#include <memory>
#include <vector>

namespace nn {

// Linear(in, out) -> LeakyReLU(0.02) -> Linear(out, out) -> [channel_norm across rows]
// -> [x * (1 + s) + b, learned s, b of shape 1 x out, init 0] -> LeakyReLU(0.02).
// Parameter names: linear1.*, linear2.*, scale, shift.
template <class T> class MLPBlock : public Module<T> {
 public:
  static constexpr double kSlope = 0.02;
  MLPBlock(int64_t in, int64_t out, bool norm, bool scale_shift, Rng& rng);
  // x [N x in] -> [N x out]. With norm, the statistics are over the N rows.
  ag::Tensor<T> forward(const ag::Tensor<T>& x) const;
  // The block after its first linear map and activation: forward(x) == after_first(
  // leaky_relu(linear1(x))). For callers that compute linear1 in parts (model_h's edges).
  ag::Tensor<T> after_first(const ag::Tensor<T>& h) const;

  std::shared_ptr<Linear<T>> linear1, linear2;
  ag::Tensor<T> scale, shift;  // undefined without scale_shift

 private:
  bool norm_;
};

// MLP blocks through the given widths, e.g. {23, 32, 16, 8}: blocks 23->32, 32->16, 16->8,
// named "0", "1", ...; every block uses the same norm / scale_shift flags.
template <class T> class MLPStack : public Module<T> {
 public:
  MLPStack(const std::vector<int64_t>& widths, bool norm, bool scale_shift, Rng& rng);
  ag::Tensor<T> forward(const ag::Tensor<T>& x) const;
  int64_t in_features() const { return widths_.front(); }
  int64_t out_features() const { return widths_.back(); }

  std::vector<std::shared_ptr<MLPBlock<T>>> blocks;

 private:
  std::vector<int64_t> widths_;
};

}  // namespace nn

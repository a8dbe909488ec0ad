// Complex fully connected layer for WIRE networks: y = x W^T + b with complex W, b, x.
//
// Initialisation (WireInit):
//  - First:  W ~ U(-1/in, 1/in)                                    (the first layer)
//  - Hidden: W ~ U(-sqrt(6/in)/omega0, sqrt(6/in)/omega0)          (later layers)
//  - PyTorch: W ~ U(-1/sqrt(in), 1/sqrt(in))                       (nn.Linear default)
// Real and imaginary parts are drawn independently; the bias is always
// U(-1/sqrt(in), 1/sqrt(in)) per part (PyTorch's default).
// Note: First/Hidden are the SIREN scheme (Sitzmann et al. 2020) that the WIRE paper's
// experiments inherit for sine-like activations; the WIRE repository's ComplexGaborLayer
// itself keeps nn.Linear's default (PyTorch). omega0 = 5 in GDSR's field.
#pragma once

#include "nn/module.hpp"
#include "nn/rng.hpp"

#include <complex>

namespace nn {

enum class WireInit { First, Hidden, PyTorch };

template <class R> class ComplexLinear : public Module<std::complex<R>> {
 public:
  using C = std::complex<R>;
  // weight [out x in] complex, bias [1 x out] complex (names "weight", "bias").
  ComplexLinear(int64_t in, int64_t out, bool bias, WireInit init, Rng& rng, double omega0 = 5.0);
  // x [N x in] complex -> [N x out] complex.
  ag::Tensor<C> forward(const ag::Tensor<C>& x) const;
  // Real input (imaginary part 0), e.g. coordinates into the first layer.
  ag::Tensor<C> forward_real(const ag::Tensor<R>& x) const;
  int64_t in_features() const { return in_; }
  int64_t out_features() const { return out_; }

  ag::Tensor<C> weight, bias;  // bias undefined when bias = false

 private:
  int64_t in_, out_;
};

}  // namespace nn

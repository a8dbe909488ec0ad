// Parameter initialisations, in place, matching PyTorch's formulas (the random streams
// differ: ours come from nn::Rng). Weights are [out x in] (fan_in = in, fan_out = out).
// Complex tensors: real and imaginary parts are drawn independently from the same law.
#pragma once

#include "autograd/tensor.hpp"
#include "nn/rng.hpp"

namespace nn {

// U(lo, hi) for every element.
template <class T> void uniform_(ag::Tensor<T>& t, double lo, double hi, Rng& rng);
// N(mean, std) for every element.
template <class T> void normal_(ag::Tensor<T>& t, double mean, double std, Rng& rng);
// torch.nn.init.kaiming_uniform_(w, a, mode="fan_in", nonlinearity="leaky_relu"):
// bound = sqrt(2 / (1 + a^2)) * sqrt(3 / fan_in). With a = sqrt(5) (nn.Linear's default)
// bound = 1 / sqrt(fan_in).
template <class T> void kaiming_uniform_(ag::Tensor<T>& t, int64_t fan_in, double a, Rng& rng);
// torch.nn.init.xavier_uniform_: bound = gain * sqrt(6 / (fan_in + fan_out)).
template <class T> void xavier_uniform_(ag::Tensor<T>& t, int64_t fan_in, int64_t fan_out, Rng& rng, double gain = 1.0);

}  // namespace nn

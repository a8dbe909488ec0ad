#include "nn/linear.hpp"

#include "autograd/ops_matmul.hpp"
#include "nn/init.hpp"

#include <cmath>

namespace nn {

template <class T> Linear<T>::Linear(int64_t in, int64_t out, bool use_bias, Rng& rng) : in_(in), out_(out) {
  if (in <= 0 || out <= 0)
    throw ag::Error("nn::Linear: sizes must be positive, got in " + std::to_string(in) + ", out " +
                    std::to_string(out));
  ag::Tensor<T> w = ag::Tensor<T>::zeros({out, in});
  kaiming_uniform_(w, in, std::sqrt(5.0), rng);
  weight = this->register_parameter("weight", w);
  if (use_bias) {
    ag::Tensor<T> b = ag::Tensor<T>::zeros({1, out});
    const double bound = 1.0 / std::sqrt(static_cast<double>(in));
    uniform_(b, -bound, bound, rng);
    bias = this->register_parameter("bias", b);
  }
}

template <class T> ag::Tensor<T> Linear<T>::forward(const ag::Tensor<T>& x) const {
  return ag::linear(x, weight, bias);
}

template class Linear<float>;
template class Linear<double>;

}  // namespace nn

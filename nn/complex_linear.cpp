#include "nn/complex_linear.hpp"

#include "autograd/ops_complex.hpp"
#include "autograd/ops_matmul.hpp"
#include "nn/init.hpp"

#include <cmath>

namespace nn {

template <class R>
ComplexLinear<R>::ComplexLinear(int64_t in, int64_t out, bool use_bias, WireInit init, Rng& rng, double omega0)
    : in_(in), out_(out) {
  if (in <= 0 || out <= 0)
    throw ag::Error("nn::ComplexLinear: sizes must be positive, got in " + std::to_string(in) + ", out " +
                    std::to_string(out));
  if (init == WireInit::Hidden && !(omega0 > 0))
    throw ag::Error("nn::ComplexLinear: omega0 must be positive for the hidden-layer init");
  const double fin = static_cast<double>(in);
  double bound = 1.0 / std::sqrt(fin);
  if (init == WireInit::First) bound = 1.0 / fin;
  if (init == WireInit::Hidden) bound = std::sqrt(6.0 / fin) / omega0;
  ag::Tensor<C> w = ag::Tensor<C>::zeros({out, in});
  uniform_(w, -bound, bound, rng);
  weight = this->register_parameter("weight", w);
  if (use_bias) {
    ag::Tensor<C> b = ag::Tensor<C>::zeros({1, out});
    const double bb = 1.0 / std::sqrt(fin);
    uniform_(b, -bb, bb, rng);
    bias = this->register_parameter("bias", b);
  }
}

template <class R> ag::Tensor<std::complex<R>> ComplexLinear<R>::forward(const ag::Tensor<C>& x) const {
  return ag::linear(x, weight, bias);
}

template <class R> ag::Tensor<std::complex<R>> ComplexLinear<R>::forward_real(const ag::Tensor<R>& x) const {
  return ag::linear(ag::complex_from_real(x), weight, bias);
}

template class ComplexLinear<float>;
template class ComplexLinear<double>;

}  // namespace nn

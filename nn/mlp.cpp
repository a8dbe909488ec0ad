#include "nn/mlp.hpp"

#include "autograd/ops_elementwise.hpp"
#include "autograd/ops_matmul.hpp"
#include "autograd/ops_norm.hpp"

namespace nn {

template <class T> MLPBlock<T>::MLPBlock(int64_t in, int64_t out, bool norm, bool scale_shift, Rng& rng) : norm_(norm) {
  linear1 = this->register_module("linear1", std::make_shared<Linear<T>>(in, out, true, rng));
  linear2 = this->register_module("linear2", std::make_shared<Linear<T>>(out, out, true, rng));
  if (scale_shift) {
    scale = this->register_parameter("scale", ag::Tensor<T>::zeros({1, out}));
    shift = this->register_parameter("shift", ag::Tensor<T>::zeros({1, out}));
  }
}

template <class T> ag::Tensor<T> MLPBlock<T>::forward(const ag::Tensor<T>& x) const {
  const T slope = static_cast<T>(kSlope);
  // Bias and activation fused into the GEMMs' output pass where they follow directly.
  return after_first(ag::linear_leaky_relu(x, linear1->weight, linear1->bias, slope));
}

template <class T> ag::Tensor<T> MLPBlock<T>::after_first(const ag::Tensor<T>& h1) const {
  const T slope = static_cast<T>(kSlope);
  if (!norm_ && !scale.defined()) return ag::linear_leaky_relu(h1, linear2->weight, linear2->bias, slope);
  ag::Tensor<T> h = linear2->forward(h1);
  if (norm_) h = ag::channel_norm(h);
  if (scale.defined()) h = ag::add(ag::add(h, ag::mul(h, scale)), shift);  // h (1 + s) + b
  return ag::leaky_relu(h, slope);
}

template <class T> MLPStack<T>::MLPStack(const std::vector<int64_t>& widths, bool norm, bool scale_shift, Rng& rng)
    : widths_(widths) {
  if (widths.size() < 2) throw ag::Error("nn::MLPStack: needs at least two widths (in and out)");
  for (size_t i = 0; i + 1 < widths.size(); ++i)
    blocks.push_back(this->register_module(
        std::to_string(i), std::make_shared<MLPBlock<T>>(widths[i], widths[i + 1], norm, scale_shift, rng)));
}

template <class T> ag::Tensor<T> MLPStack<T>::forward(const ag::Tensor<T>& x) const {
  ag::Tensor<T> h = x;
  for (const auto& b : blocks) h = b->forward(h);
  return h;
}

template class MLPBlock<float>;
template class MLPBlock<double>;
template class MLPStack<float>;
template class MLPStack<double>;

}  // namespace nn

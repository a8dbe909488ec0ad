#include "nn/adamw.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace nn {

namespace {
// Pointers to a slot's values and gradient as arrays of reals (complex = interleaved re, im).
template <class R> struct RealView {
  R* value = nullptr;
  const R* grad = nullptr;
  int64_t n = 0;
};
template <class R> RealView<R> view(typename AdamW<R>::Slot& s) {
  RealView<R> r;
  if (s.complex) {
    auto* node = static_cast<ag::Node<std::complex<R>>*>(s.node.get());
    if (node->grad.empty()) return r;
    r.value = reinterpret_cast<R*>(node->value.data());
    r.grad = reinterpret_cast<const R*>(node->grad.data());
    r.n = 2 * static_cast<int64_t>(node->value.size());
  } else {
    auto* node = static_cast<ag::Node<R>*>(s.node.get());
    if (node->grad.empty()) return r;
    r.value = node->value.data();
    r.grad = node->grad.data();
    r.n = static_cast<int64_t>(node->value.size());
  }
  return r;
}
}  // namespace

void check_adamw_options(const AdamWOptions& o) {
  auto refuse = [](const char* key, const char* range, double v) {
    throw ag::Error(std::string("AdamW: ") + key + " must be " + range + ", got " + std::to_string(v));
  };
  if (!std::isfinite(o.lr) || o.lr < 0) refuse("lr", "finite and >= 0", o.lr);
  if (!(o.beta1 >= 0 && o.beta1 < 1)) refuse("beta1", "in [0, 1)", o.beta1);
  if (!(o.beta2 >= 0 && o.beta2 < 1)) refuse("beta2", "in [0, 1)", o.beta2);
  if (!std::isfinite(o.eps) || o.eps <= 0) refuse("eps", "finite and > 0", o.eps);
  if (!std::isfinite(o.weight_decay) || o.weight_decay < 0) refuse("weight_decay", "finite and >= 0", o.weight_decay);
}

template <class R> int64_t AdamW<R>::Slot::reals() const { return (complex ? 2 : 1) * node->numel(); }

template <class R> AdamW<R>::AdamW(const std::vector<std::pair<std::string, ag::Tensor<R>>>& params, AdamWOptions opt)
    : opt_(opt) {
  check_adamw_options(opt_);
  add_all(params);
}

template <class R> void AdamW<R>::add(const std::string& name, const ag::Tensor<R>& p) {
  for (const auto& s : slots_)
    if (s.name == name) throw ag::Error("AdamW: duplicate parameter name '" + name + "'");
  Slot s;
  s.name = name;
  s.node = p.node_ptr();
  s.complex = false;
  slots_.push_back(std::move(s));
}

template <class R> void AdamW<R>::add(const std::string& name, const ag::Tensor<std::complex<R>>& p) {
  for (const auto& s : slots_)
    if (s.name == name) throw ag::Error("AdamW: duplicate parameter name '" + name + "'");
  Slot s;
  s.name = name;
  s.node = p.node_ptr();
  s.complex = true;
  slots_.push_back(std::move(s));
}

template <class R> void AdamW<R>::step() {
  ++steps_;
  const double lr = opt_.lr, b1 = opt_.beta1, b2 = opt_.beta2;
  const R decay = static_cast<R>(1.0 - lr * opt_.weight_decay);
  const R rb2 = static_cast<R>(b2);
  const R one_b1 = static_cast<R>(1.0 - b1), one_b2 = static_cast<R>(1.0 - b2);
  const R eps = static_cast<R>(opt_.eps);
  for (auto& s : slots_) {
    RealView<R> p = view<R>(s);
    if (!p.value) continue;  // no gradient this step
    const size_t n = static_cast<size_t>(p.n);
    if (s.m.size() != n) {
      s.m.assign(n, R(0));
      s.v.assign(n, R(0));
    }
    if (opt_.amsgrad && s.vmax.size() != n) s.vmax.assign(n, R(0));
    ++s.step;
    const double t = static_cast<double>(s.step);
    const double bc1 = 1.0 - std::pow(b1, t), bc2 = 1.0 - std::pow(b2, t);
    const R step_size = static_cast<R>(lr / bc1);
    const R bc2_sqrt = static_cast<R>(std::sqrt(bc2));
    R* m = s.m.data();
    R* v = s.v.data();
    R* vmax = opt_.amsgrad ? s.vmax.data() : nullptr;
    const bool ams = opt_.amsgrad;
#pragma omp parallel for schedule(static) if (p.n >= ag::kParallelMin)
    for (int64_t i = 0; i < p.n; ++i) {
      const R g = p.grad[i];
      R x = p.value[i] * decay;
      m[i] += one_b1 * (g - m[i]);  // torch's lerp(m, g, 1 - beta1)
      v[i] = rb2 * v[i] + one_b2 * g * g;
      R vv = v[i];
      if (ams) {
        vmax[i] = std::max(vmax[i], v[i]);
        vv = vmax[i];
      }
      const R denom = std::sqrt(vv) / bc2_sqrt + eps;
      p.value[i] = x - step_size * m[i] / denom;
    }
  }
}

template <class R> void AdamW<R>::zero_grad() {
  for (auto& s : slots_) s.node->zero_grad();
}

template class AdamW<float>;
template class AdamW<double>;

}  // namespace nn

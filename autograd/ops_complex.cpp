#include "autograd/ops_complex.hpp"

#include <cmath>

namespace ag {

template <class R> Tensor<std::complex<R>> complex_from(const Tensor<R>& re, const Tensor<R>& im) {
  using C = std::complex<R>;
  check_same_shape("complex_from", re.shape(), im.shape());
  auto out = new_output<C>(re.shape());
  const int64_t n = re.numel();
  const R *a = re.data(), *b = im.data();
  C* o = out.data();
#pragma omp parallel for if (n > kParallelMin)
  for (int64_t i = 0; i < n; ++i) o[i] = C(a[i], b[i]);
  record(out.node(), {re.node_ptr(), im.node_ptr()}, [an = &re.node(), bn = &im.node(), on = &out.node(), n] {
    const C* g = on->grad.data();
    if (an->requires_grad) {
      an->ensure_grad();
      for (int64_t i = 0; i < n; ++i) an->grad[i] += g[i].real();
    }
    if (bn->requires_grad) {
      bn->ensure_grad();
      for (int64_t i = 0; i < n; ++i) bn->grad[i] += g[i].imag();
    }
  });
  return out;
}

template <class R> Tensor<std::complex<R>> complex_from_real(const Tensor<R>& re) {
  using C = std::complex<R>;
  auto out = new_output<C>(re.shape());
  const int64_t n = re.numel();
  const R* a = re.data();
  C* o = out.data();
  for (int64_t i = 0; i < n; ++i) o[i] = C(a[i], R(0));
  record(out.node(), {re.node_ptr()}, [an = &re.node(), on = &out.node(), n] {
    if (!an->requires_grad) return;
    an->ensure_grad();
    for (int64_t i = 0; i < n; ++i) an->grad[i] += on->grad[i].real();
  });
  return out;
}

template <class R> Tensor<R> real(const Tensor<std::complex<R>>& z) {
  auto out = new_output<R>(z.shape());
  const int64_t n = z.numel();
  for (int64_t i = 0; i < n; ++i) out.data()[i] = z.data()[i].real();
  record(out.node(), {z.node_ptr()}, [zn = &z.node(), on = &out.node(), n] {
    if (!zn->requires_grad) return;
    zn->ensure_grad();
    for (int64_t i = 0; i < n; ++i) zn->grad[i] += std::complex<R>(on->grad[i], R(0));
  });
  return out;
}

template <class R> Tensor<R> imag(const Tensor<std::complex<R>>& z) {
  auto out = new_output<R>(z.shape());
  const int64_t n = z.numel();
  for (int64_t i = 0; i < n; ++i) out.data()[i] = z.data()[i].imag();
  record(out.node(), {z.node_ptr()}, [zn = &z.node(), on = &out.node(), n] {
    if (!zn->requires_grad) return;
    zn->ensure_grad();
    for (int64_t i = 0; i < n; ++i) zn->grad[i] += std::complex<R>(R(0), on->grad[i]);
  });
  return out;
}

// |z| = hypot(a, b); dL/da + i dL/db = g z / |z| (0 at z = 0), formed as g (z / |z|): the unit
// z / |z| is exact for every finite z, where g / |z| overflows once |z| is subnormal.
template <class R> Tensor<R> modulus(const Tensor<std::complex<R>>& z) {
  auto out = new_output<R>(z.shape());
  const int64_t n = z.numel();
  const std::complex<R>* pz = z.data();
  R* o = out.data();
#pragma omp parallel for if (n > kParallelMin)
  for (int64_t i = 0; i < n; ++i) o[i] = std::abs(pz[i]);
  record(out.node(), {z.node_ptr()}, [zn = &z.node(), on = &out.node(), n] {
    if (!zn->requires_grad) return;
    zn->ensure_grad();
    const R* g = on->grad.data();
    const R* m = on->value.data();
    const std::complex<R>* pz = zn->value.data();
    std::complex<R>* gz = zn->grad.data();
#pragma omp parallel for if (n > kParallelMin)
    for (int64_t i = 0; i < n; ++i)
      if (m[i] > 0) gz[i] += g[i] * (pz[i] / m[i]);
  });
  return out;
}

#define AG_INSTANTIATE(R)                                                               \
  template Tensor<std::complex<R>> complex_from<R>(const Tensor<R>&, const Tensor<R>&); \
  template Tensor<std::complex<R>> complex_from_real<R>(const Tensor<R>&);              \
  template Tensor<R> real<R>(const Tensor<std::complex<R>>&);                           \
  template Tensor<R> imag<R>(const Tensor<std::complex<R>>&);                           \
  template Tensor<R> modulus<R>(const Tensor<std::complex<R>>&);
AG_INSTANTIATE(float)
AG_INSTANTIATE(double)
#undef AG_INSTANTIATE

}  // namespace ag

#include "autograd/ops_wire.hpp"

#include <cmath>

namespace ag {

template <class R> Tensor<std::complex<R>> wire(const Tensor<std::complex<R>>& x, R omega0, R s0) {
  using C = std::complex<R>;
  auto out = new_output<C>(x.shape());
  const int64_t n = x.numel();
  const C* px = x.data();
  C* o = out.data();
  const R s2 = s0 * s0;
#pragma omp parallel for if (n > kParallelMin)
  for (int64_t i = 0; i < n; ++i) {
    const R a = px[i].real(), b = px[i].imag();
    // Re(E) as one sum: never exp(-omega0 b) alone (overflows for b << 0).
    const R mag = std::exp(-omega0 * b - s2 * (a * a + b * b));
    const R ph = omega0 * a;
    o[i] = C(mag * std::cos(ph), mag * std::sin(ph));
  }
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), n, omega0, s2] {
    if (!xn->requires_grad) return;
    xn->ensure_grad();
    const C* g = on->grad.data();
    const C* psi = on->value.data();
    const C* px = xn->value.data();
    C* gx = xn->grad.data();
#pragma omp parallel for if (n > kParallelMin)
    for (int64_t i = 0; i < n; ++i) {
      const R a = px[i].real(), b = px[i].imag();
      const C t = std::conj(g[i]) * psi[i];
      // psi underflowed to 0 (|x| > ~2.7 / s0) or no gradient flows: the contribution is 0.
      // Skipped, not multiplied: the factor 2 s0^2 a is inf for |a| > DBL_MAX / (2 s0^2)
      // (9e305 at s0 = 10; 1.7e36 in float32), and 0 * inf would be NaN.
      if (t == C(0)) continue;
      const R da = (t * C(-2 * s2 * a, omega0)).real();
      const R db = (t * C(-omega0 - 2 * s2 * b, R(0))).real();
      gx[i] += C(da, db);
    }
  });
  return out;
}

template Tensor<std::complex<float>> wire<float>(const Tensor<std::complex<float>>&, float, float);
template Tensor<std::complex<double>> wire<double>(const Tensor<std::complex<double>>&, double, double);

}  // namespace ag

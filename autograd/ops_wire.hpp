// WIRE: the complex Gabor wavelet activation of Saragadam et al. 2023, used by the GDSR
// hyper-network's per-triangle fields:
//     psi(x) = exp(i * omega0 * x - |s0 * x|^2)
// for complex x = a + ib:  exponent E = (-omega0 b - s0^2 (a^2 + b^2)) + i omega0 a.
// The real part of E is formed as ONE sum before exp, so large |x| underflows cleanly to 0
// instead of overflowing exp(-omega0 b) on its own.
// Backward (grad g = dL/dRe psi + i dL/dIm psi):
//     dL/da = Re(conj(g) psi (i omega0 - 2 s0^2 a)),  dL/db = Re(conj(g) psi (-omega0 - 2 s0^2 b)).
// Valid range: any finite x for s0 > 0 (value and gradient finite and exact from |x| = 0 up
// to the largest float, in float32 and float64; where psi underflows to 0 so does the
// gradient). At s0 = 0 the Gaussian envelope is gone and |psi| =
// e^{-omega0 b} overflows for b < -88.7 / omega0 (float32); the model config refuses s0 <= 0.
#pragma once

#include "autograd/tensor.hpp"

#include <complex>

namespace ag {

template <class R> Tensor<std::complex<R>> wire(const Tensor<std::complex<R>>& x, R omega0 = R(5), R s0 = R(10));

}  // namespace ag

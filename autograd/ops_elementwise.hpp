// Elementwise ops. Binary ops broadcast over 2-D tensors (rows x cols): each operand
// dimension must equal the result's or be 1 ([R x C] op [1 x C] is a row broadcast,
// [R x 1] a column broadcast, [1 x 1] a scalar). Tensors of other ranks must have equal
// shapes (or one element). Backward sums the gradient over broadcast dimensions.
#pragma once

#include "autograd/tensor.hpp"

namespace ag {

// Any scalar type (float, double, complex<float>, complex<double>).
template <class T> Tensor<T> add(const Tensor<T>& a, const Tensor<T>& b);
template <class T> Tensor<T> sub(const Tensor<T>& a, const Tensor<T>& b);
template <class T> Tensor<T> mul(const Tensor<T>& a, const Tensor<T>& b);
// div needs b != 0: b = 0 gives inf (NaN for 0 / 0) and so do its gradients 1 / b and
// -a / b^2, the latter already once |a| / b^2 exceeds the largest float. Complex: the same
// limits on |b|, and where a result's modulus exceeds the largest float its parts are inf or
// NaN (e.g. the gradient at subnormal |b|).
template <class T> Tensor<T> div(const Tensor<T>& a, const Tensor<T>& b);
template <class T> Tensor<T> neg(const Tensor<T>& a);
template <class T> Tensor<T> add_scalar(const Tensor<T>& a, T s);
template <class T> Tensor<T> mul_scalar(const Tensor<T>& a, T s);

template <class T> Tensor<T> operator+(const Tensor<T>& a, const Tensor<T>& b) { return add(a, b); }
template <class T> Tensor<T> operator-(const Tensor<T>& a, const Tensor<T>& b) { return sub(a, b); }
template <class T> Tensor<T> operator*(const Tensor<T>& a, const Tensor<T>& b) { return mul(a, b); }
template <class T> Tensor<T> operator/(const Tensor<T>& a, const Tensor<T>& b) { return div(a, b); }
template <class T> Tensor<T> operator-(const Tensor<T>& a) { return neg(a); }
template <class T> Tensor<T> operator+(const Tensor<T>& a, T s) { return add_scalar(a, s); }
template <class T> Tensor<T> operator-(const Tensor<T>& a, T s) { return add_scalar(a, T(-s)); }
template <class T> Tensor<T> operator*(const Tensor<T>& a, T s) { return mul_scalar(a, s); }
template <class T> Tensor<T> operator*(T s, const Tensor<T>& a) { return mul_scalar(a, s); }

// Real scalar types only (float, double). Valid input ranges follow IEEE arithmetic; where a
// value or gradient leaves the float range it becomes inf or NaN (never clamped silently):
// exp (and its gradient, exp itself) overflows above ~88.7 (float32) / ~709.8 (float64).
template <class T> Tensor<T> exp(const Tensor<T>& x);
// Needs x > 0: log(0) = -inf with gradient +inf, log(x < 0) = NaN. For x below 1 / the
// largest float (5.6e-309 float64, 2.9e-39 float32: subnormals) the value is finite but the
// gradient 1 / x exceeds the largest float: +inf.
template <class T> Tensor<T> log(const Tensor<T>& x);
// Needs x >= 0 (NaN below). At exactly 0 the gradient is +inf, and a zero upstream gradient
// (a masked entry) then gives 0 * inf = NaN: add an eps first where x can reach 0.
template <class T> Tensor<T> sqrt(const Tensor<T>& x);
template <class T> Tensor<T> sin(const Tensor<T>& x);
template <class T> Tensor<T> cos(const Tensor<T>& x);
template <class T> Tensor<T> tanh(const Tensor<T>& x);
template <class T> Tensor<T> abs(const Tensor<T>& x);  // d|x|/dx at 0 taken as 0
template <class T> Tensor<T> square(const Tensor<T>& x);
// x^p; for non-integer p needs x > 0 (NaN below), and for p < 1 the gradient p x^(p-1) is
// inf at x = 0 (as sqrt's).
template <class T> Tensor<T> pow(const Tensor<T>& x, T p);
template <class T> Tensor<T> relu(const Tensor<T>& x);
template <class T> Tensor<T> leaky_relu(const Tensor<T>& x, T slope);
template <class T> Tensor<T> sigmoid(const Tensor<T>& x);
// Needs lo <= hi (ag::Error otherwise); gradient 0 outside [lo, hi], 1 on its ends.
template <class T> Tensor<T> clamp(const Tensor<T>& x, T lo, T hi);
// Same shapes; grad at (0,0) taken as 0. Valid for all finite y, x: the gradient is scaled
// first (as hypot), exact down to subnormal and up to near-overflow magnitudes.
template <class T> Tensor<T> atan2(const Tensor<T>& y, const Tensor<T>& x);

}  // namespace ag

// Complex tensors: conversion to and from real parts, modulus, and the WIRE activation.
// (add/sub/mul/div, matmul, linear, grouped_linear, index ops, sum/mean work on complex
// tensors too.) Gradient convention: see tensor.hpp (grad = dL/dRe + i dL/dIm).
#pragma once

#include "autograd/tensor.hpp"

#include <complex>

namespace ag {

template <class R> Tensor<std::complex<R>> complex_from(const Tensor<R>& re, const Tensor<R>& im);
template <class R> Tensor<std::complex<R>> complex_from_real(const Tensor<R>& re);  // im = 0
template <class R> Tensor<R> real(const Tensor<std::complex<R>>& z);
template <class R> Tensor<R> imag(const Tensor<std::complex<R>>& z);
// |z| (hypot: no overflow or underflow of |z|^2); gradient z / |z|, exact for every finite z
// from subnormal to near-overflow moduli, and 0 at z = 0.
template <class R> Tensor<R> modulus(const Tensor<std::complex<R>>& z);

}  // namespace ag

// Internal to ops_grouped.cpp: SIMD kernels of the complex grouped linear map's BACKWARD
// pass for weights stored as two real planes (the hyper-network's output, GDSR's field: one
// 64 x 64 complex matrix per LR triangle, applied to the ~4-7 HR samples inside it).
//
// grouped_kernel.hpp puts a group's ROWS in the SIMD lanes, which leaves lanes empty when a
// group has fewer rows than a packet holds (8 complex rows with AVX-512 floats; the field
// has ~4.3 per triangle). These kernels put the weights' contiguous index (the input i of
// W[o][i], row-major out x in) in the lanes instead, so that every lane works whatever the
// row count:
//   backward_x  dx[r][i] += sum_o g[r][o] conj(W[o][i])   lanes over i, g broadcast;
//   backward_w  dW[o][i] += sum_r g[r][o] conj(x[r][i])   lanes over i, g broadcast.
// (The forward y[r][o] = sum_i W[o][i] x[r][i] has no lane-wise form in this layout: a
// dot-product kernel with a transposing reduction measured slower than grouped_kernel's
// forward, which ops_grouped.cpp keeps using: 9.5 vs 11.8 ms at 6.5 rows per group, equal
// at 4.3, one thread, bench_mlp's sizes.)
// Measured the same way, at 6.5 / 4.3 rows per group: backward_x 7.4 / 4.5 ms against
// 10.0 / 8.5 ms for grouped_kernel's, backward_w 7.2 / 5.7 against 9.2 / 7.9 ms.
// Complex products in planes: (a + ib)(c + id) = (ac - bd) + i(ad + bc), two FMAs per plane.
// Results equal the plain complex sums up to floating-point rounding order.
#pragma once

#include "autograd/grouped_kernel.hpp"

#include <Eigen/Core>
#include <complex>
#include <cstdint>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace ag::grouped_planes_kernel {

using grouped_kernel::Buffer;
using grouped_kernel::CView;
using grouped_kernel::kLanes;
using grouped_kernel::Packet;
using grouped_kernel::View;

// x [n x in] interleaved -> planes xr, xi, and nxi = -xi (row stride in).
template <class R> void split_planes(const std::complex<R>* x, int64_t n, int64_t in, Buffer<R>& xr, Buffer<R>& xi,
                                     Buffer<R>& nxi) {
  xr.resize(static_cast<size_t>(n * in));
  xi.resize(xr.size());
  nxi.resize(xr.size());
  const R* __restrict v = reinterpret_cast<const R*>(x);
  R* __restrict a = xr.data();
  R* __restrict b = xi.data();
  R* __restrict c = nxi.data();
  for (int64_t e = 0; e < n * in; ++e) a[e] = v[2 * e], b[e] = v[2 * e + 1], c[e] = -v[2 * e + 1];
}

// d[l] += (re[l], im[l]) for the L lanes of two packets (planes back to interleaved).
template <class R> inline void add_interleaved(std::complex<R>* d, const Packet<R>& re, const Packet<R>& im) {
  constexpr int L = kLanes<R>;
  alignas(64) R tr[L], ti[L];
  Eigen::internal::pstore(tr, re);
  Eigen::internal::pstore(ti, im);
  for (int l = 0; l < L; ++l) d[l] += std::complex<R>(tr[l], ti[l]);
}
#if defined(__AVX512F__)
template <> inline void add_interleaved<float>(std::complex<float>* d, const Packet<float>& re, const Packet<float>& im) {
  const __m512i lo = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
  const __m512i hi = _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
  float* p = reinterpret_cast<float*>(d);
  _mm512_storeu_ps(p, _mm512_add_ps(_mm512_loadu_ps(p), _mm512_permutex2var_ps(re, lo, im)));
  _mm512_storeu_ps(p + 16, _mm512_add_ps(_mm512_loadu_ps(p + 16), _mm512_permutex2var_ps(re, hi, im)));
}
#endif

// dx[n x in] += g[n x out] conj(W) for one group: RB rows at a time, inputs in blocks of IP
// packets, accumulated in registers over all outputs. IN, OUT: the sizes as compile-time
// constants (0: in_rt, out_rt), for constant address offsets between rows.
template <class R, int RB, int IP, int IN, int OUT>
inline void backward_x_block(const std::complex<R>* g, const CView<R>& W, std::complex<R>* dx, int64_t in_rt,
                             int64_t out_rt, int64_t i0) {
  using namespace Eigen::internal;
  using P = Packet<R>;
  constexpr int L = kLanes<R>;
  const int64_t in = IN > 0 ? IN : in_rt, out = OUT > 0 ? OUT : out_rt;
  P re[RB][IP], im[RB][IP];
  for (int r = 0; r < RB; ++r)
    for (int p = 0; p < IP; ++p) re[r][p] = im[r][p] = pset1<P>(R(0));
  const R* gv = reinterpret_cast<const R*>(g);
  const R* wr_row = W.re + i0;
  const R* wi_row = W.im + i0;
  for (int64_t o = 0; o < out; ++o, wr_row += in, wi_row += in, gv += 2) {
    P wr[IP], wi[IP], nwi[IP];
    for (int p = 0; p < IP; ++p) {
      wr[p] = ploadu<P>(wr_row + p * L), wi[p] = ploadu<P>(wi_row + p * L);
      nwi[p] = pnegate(wi[p]);
    }
    for (int r = 0; r < RB; ++r) {
      const P ga = pset1<P>(gv[2 * r * out]), gb = pset1<P>(gv[2 * r * out + 1]);
      // conj(w) g = (wr ga + wi gb) + i (wr gb - wi ga)
      for (int p = 0; p < IP; ++p) {
        re[r][p] = pmadd(ga, wr[p], pmadd(gb, wi[p], re[r][p]));
        im[r][p] = pmadd(gb, wr[p], pmadd(ga, nwi[p], im[r][p]));
      }
    }
  }
  for (int r = 0; r < RB; ++r)
    for (int p = 0; p < IP; ++p) add_interleaved<R>(dx + r * in + i0 + p * L, re[r][p], im[r][p]);
}

// Few rows: wider input blocks, so that enough independent accumulators hide the FMA latency.
template <class R, int RB, int IN, int OUT>
void backward_x_rows(const std::complex<R>* g, const CView<R>& W, std::complex<R>* dx, int64_t in, int64_t out) {
  constexpr int L = kLanes<R>, IP = RB <= 3 ? 4 : 2;
  int64_t i = 0;
  for (; i + IP * L <= in; i += IP * L) backward_x_block<R, RB, IP, IN, OUT>(g, W, dx, in, out, i);
  for (; i + L <= in; i += L) backward_x_block<R, RB, 1, IN, OUT>(g, W, dx, in, out, i);
}

template <class R, int IN, int OUT>
void backward_x_impl(const std::complex<R>* g, const CView<R>& W, std::complex<R>* dx, int64_t n, int64_t in,
                     int64_t out) {
  constexpr int L = kLanes<R>, RB = 6;
  const int64_t passes = (n + RB - 1) / RB, per_pass = (n + passes - 1) / passes;  // 7 rows: 4 + 3
  for (int64_t r0 = 0; r0 < n; r0 += per_pass) {
    const int64_t rows = std::min<int64_t>(per_pass, n - r0);
    const std::complex<R>* gr = g + r0 * out;
    std::complex<R>* dr = dx + r0 * in;
    switch (rows) {  // the row count as a constant: the accumulators stay in registers
      case 1: backward_x_rows<R, 1, IN, OUT>(gr, W, dr, in, out); break;
      case 2: backward_x_rows<R, 2, IN, OUT>(gr, W, dr, in, out); break;
      case 3: backward_x_rows<R, 3, IN, OUT>(gr, W, dr, in, out); break;
      case 4: backward_x_rows<R, 4, IN, OUT>(gr, W, dr, in, out); break;
      case 5: backward_x_rows<R, 5, IN, OUT>(gr, W, dr, in, out); break;
      default: backward_x_rows<R, RB, IN, OUT>(gr, W, dr, in, out); break;
    }
    for (int64_t k = in / L * L; k < in; ++k)  // inputs beyond the whole packets
      for (int64_t r = 0; r < rows; ++r) {
        std::complex<R> acc(0);
        for (int64_t o = 0; o < out; ++o)
          acc += gr[r * out + o] * std::complex<R>(W.re[o * in + k], -W.im[o * in + k]);
        dr[r * in + k] += acc;
      }
  }
}

template <class R> void backward_x(const std::complex<R>* g, const CView<R>& W, std::complex<R>* dx, int64_t n,
                                   int64_t in, int64_t out) {
  if (in == 64 && out == 64)  // the field's hidden layers
    backward_x_impl<R, 64, 64>(g, W, dx, n, in, out);
  else
    backward_x_impl<R, 0, 0>(g, W, dx, n, in, out);
}

// dW[out x in] += g^T conj(x) for one group of n rows, dW as planes: O outputs x Q packets
// of inputs per block, each dW element loaded and stored once.
template <class R> void backward_w(const std::complex<R>* g, const std::complex<R>* x, const View<R>& dW, int64_t n,
                                   int64_t in, int64_t out, Buffer<R>& xr, Buffer<R>& xi, Buffer<R>& nxi) {
  using namespace Eigen::internal;
  using P = Packet<R>;
  constexpr int L = kLanes<R>, O = 2, Q = 4;
  split_planes(x, n, in, xr, xi, nxi);
  const R* gv = reinterpret_cast<const R*>(g);
  auto block = [&](auto o_count, auto q_count, int64_t o, int64_t i) {
    constexpr int OC = decltype(o_count)::value, QC = decltype(q_count)::value;
    P re[OC][QC], im[OC][QC];
    for (int j = 0; j < OC; ++j)
      for (int q = 0; q < QC; ++q)
        re[j][q] = ploadu<P>(dW.re + (o + j) * in + i + q * L), im[j][q] = ploadu<P>(dW.im + (o + j) * in + i + q * L);
    for (int64_t r = 0; r < n; ++r) {
      P ar[QC], ai[QC], an[QC];
      for (int q = 0; q < QC; ++q) {
        ar[q] = ploadu<P>(xr.data() + r * in + i + q * L);
        ai[q] = ploadu<P>(xi.data() + r * in + i + q * L);
        an[q] = ploadu<P>(nxi.data() + r * in + i + q * L);
      }
      for (int j = 0; j < OC; ++j) {
        const P ga = pset1<P>(gv[2 * (r * out + o + j)]), gb = pset1<P>(gv[2 * (r * out + o + j) + 1]);
        // g conj(x) = (ga xr + gb xi) + i (gb xr - ga xi)
        for (int q = 0; q < QC; ++q) {
          re[j][q] = pmadd(ga, ar[q], pmadd(gb, ai[q], re[j][q]));
          im[j][q] = pmadd(gb, ar[q], pmadd(ga, an[q], im[j][q]));
        }
      }
    }
    for (int j = 0; j < OC; ++j)
      for (int q = 0; q < QC; ++q) {
        pstoreu(dW.re + (o + j) * in + i + q * L, re[j][q]);
        pstoreu(dW.im + (o + j) * in + i + q * L, im[j][q]);
      }
  };
  using I1 = std::integral_constant<int, 1>;
  using IO = std::integral_constant<int, O>;
  using IQ = std::integral_constant<int, Q>;
  const int64_t ip = in / L * L;  // inputs in whole packets
  int64_t o = 0;
  for (; o + O <= out; o += O) {
    int64_t i = 0;
    for (; i + Q * L <= ip; i += Q * L) block(IO{}, IQ{}, o, i);
    for (; i < ip; i += L) block(IO{}, I1{}, o, i);
  }
  for (; o < out; ++o) {
    int64_t i = 0;
    for (; i + Q * L <= ip; i += Q * L) block(I1{}, IQ{}, o, i);
    for (; i < ip; i += L) block(I1{}, I1{}, o, i);
  }
  for (int64_t k = ip; k < in; ++k)  // inputs beyond the whole packets
    for (int64_t oo = 0; oo < out; ++oo) {
      std::complex<R> acc(0);
      for (int64_t r = 0; r < n; ++r) acc += g[r * out + oo] * std::conj(x[r * in + k]);
      dW.re[oo * in + k] += acc.real();
      dW.im[oo * in + k] += acc.imag();
    }
}

}  // namespace ag::grouped_planes_kernel

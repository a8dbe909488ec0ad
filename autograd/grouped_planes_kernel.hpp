// Internal to ops_grouped.cpp: SIMD kernels of the complex grouped linear map for weights
// stored as two real planes (the hyper-network's output, GDSR's field: one 64 x 64 complex
// matrix per LR triangle, applied to the ~4-7 HR samples inside it).
//
// grouped_kernel.hpp puts a group's ROWS in the SIMD lanes, which leaves lanes empty when a
// group has fewer rows than a packet holds (8 complex rows with AVX-512 floats; the field
// has ~4.3 per triangle). These kernels put a matrix's contiguous index in the lanes and
// broadcast the rows' values, so that every lane works whatever the row count:
//   backward_x  dx[r][i] += sum_o g[r][o] conj(W[o][i])   lanes over i (W as stored);
//   backward_w  dW[o][i] += sum_r g[r][o] conj(x[r][i])   lanes over i (or = when the
//               op has claimed a fresh dW: no zero fill and no read of dW);
//   forward     y[r][o]  += sum_i x[r][i] W^T[i][o]       lanes over o, W transposed into
//               scratch first (L x L register tiles).
// Each group's weights are used by a handful of rows, so the op streams them from memory
// (~6 flops per byte); every kernel prefetches the next group's weights (or dW) while it
// works on the current one, spread over its steps.
// Measured against grouped_kernel's on bench_mlp's sizes (one thread, 6.5 rows per group):
// forward 6.4 vs 9.0-9.6 ms, backward_x 5.5 vs 10.1 ms, backward_w 6.9 vs 9.2 ms.
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
template <class R>
void split_planes(const std::complex<R>* x, int64_t n, int64_t in, Buffer<R>& xr, Buffer<R>& xi, Buffer<R>& nxi) {
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
template <>
inline void add_interleaved<float>(std::complex<float>* d, const Packet<float>& re, const Packet<float>& im) {
  const __m512i lo = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
  const __m512i hi = _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
  float* p = reinterpret_cast<float*>(d);
  _mm512_storeu_ps(p, _mm512_add_ps(_mm512_loadu_ps(p), _mm512_permutex2var_ps(re, lo, im)));
  _mm512_storeu_ps(p + 16, _mm512_add_ps(_mm512_loadu_ps(p + 16), _mm512_permutex2var_ps(re, hi, im)));
}
#endif

// dst[n x J] += a[n x K] op(M) for one group, M [K x J] row-major planes, op = conj
// (Conj) or identity: the rows of M in the lanes, a broadcast. RB rows at a time, columns
// in blocks of JP packets, accumulated in registers over all K. KD, JD: K and J as
// compile-time constants (0: k_rt, j_rt), for constant address offsets between rows.
template <class R, bool Conj, int RB, int JP, int KD, int JD>
inline void lanes_block(const std::complex<R>* a, const CView<R>& M, std::complex<R>* dst, int64_t k_rt, int64_t j_rt,
                        int64_t j0, const char* pf_re = nullptr, const char* pf_im = nullptr, int pf_per_k = 0) {
  using namespace Eigen::internal;
  using P = Packet<R>;
  constexpr int L = kLanes<R>;
  const int64_t K = KD > 0 ? KD : k_rt, J = JD > 0 ? JD : j_rt;
  P re[RB][JP], im[RB][JP];
  for (int r = 0; r < RB; ++r)
    for (int p = 0; p < JP; ++p) re[r][p] = im[r][p] = pset1<P>(R(0));
  const R* av = reinterpret_cast<const R*>(a);
  const R* mr_row = M.re + j0;
  const R* mi_row = M.im + j0;
  for (int64_t k = 0; k < K; ++k, mr_row += J, mi_row += J, av += 2) {
    for (int l = 0; l < pf_per_k; ++l)
      __builtin_prefetch(pf_re + 64 * (k * pf_per_k + l)), __builtin_prefetch(pf_im + 64 * (k * pf_per_k + l));
    P mr[JP], mi[JP], nmi[JP];
    for (int p = 0; p < JP; ++p) {
      mr[p] = ploadu<P>(mr_row + p * L), mi[p] = ploadu<P>(mi_row + p * L);
      nmi[p] = pnegate(mi[p]);
    }
    for (int r = 0; r < RB; ++r) {
      const P ga = pset1<P>(av[2 * r * K]), gb = pset1<P>(av[2 * r * K + 1]);
      // conj(m) a = (mr ga + mi gb) + i (mr gb - mi ga);  m a = (mr ga - mi gb) + i (mr gb + mi ga)
      for (int p = 0; p < JP; ++p) {
        re[r][p] = pmadd(ga, mr[p], pmadd(gb, Conj ? mi[p] : nmi[p], re[r][p]));
        im[r][p] = pmadd(gb, mr[p], pmadd(ga, Conj ? nmi[p] : mi[p], im[r][p]));
      }
    }
  }
  for (int r = 0; r < RB; ++r)
    for (int p = 0; p < JP; ++p) add_interleaved<R>(dst + r * J + j0 + p * L, re[r][p], im[r][p]);
}

// Packets per column block for a pass of `rows` rows: few rows get wider blocks, so that
// enough independent accumulators hide the FMA latency.
constexpr int column_packets(int64_t rows) { return rows <= 3 ? 4 : 2; }

template <class R, bool Conj, int RB, int KD, int JD>
void lanes_rows(const std::complex<R>* a, const CView<R>& M, std::complex<R>* dst, int64_t K, int64_t J,
                const CView<R>* next = nullptr, int64_t* pf_line = nullptr, int64_t pf_lines = 0, int pf_per_k = 0) {
  constexpr int L = kLanes<R>, JP = column_packets(RB);
  int64_t j = 0;
  for (; j + JP * L <= J; j += JP * L) {
    const char* pr = nullptr;
    const char* pi = nullptr;
    int per_k = 0;
    if (next && *pf_line < pf_lines) {
      pr = reinterpret_cast<const char*>(next->re) + 64 * *pf_line;
      pi = reinterpret_cast<const char*>(next->im) + 64 * *pf_line;
      per_k = static_cast<int>(std::min<int64_t>(pf_per_k, (pf_lines - *pf_line) / K));
      *pf_line += per_k * K;
    }
    lanes_block<R, Conj, RB, JP, KD, JD>(a, M, dst, K, J, j, pr, pi, per_k);
  }
  for (; j + L <= J; j += L) lanes_block<R, Conj, RB, 1, KD, JD>(a, M, dst, K, J, j);
}

template <class R, bool Conj, int KD, int JD> void lanes_product_impl(const std::complex<R>* a, const CView<R>& M,
                                                                      std::complex<R>* dst, int64_t n, int64_t K,
                                                                      int64_t J, const CView<R>* next = nullptr) {
  constexpr int L = kLanes<R>, RB = 6;
  // The next group's matrix (`next`, or null) is prefetched meanwhile, a few cache lines of
  // each plane per step of k, spread over all column blocks of this group.
  const int64_t passes = (n + RB - 1) / RB, per_pass = (n + passes - 1) / passes;  // 7 rows: 4 + 3
  int64_t blocks = 0;
  for (int64_t r0 = 0; r0 < n; r0 += per_pass) blocks += J / (column_packets(std::min<int64_t>(per_pass, n - r0)) * L);
  int64_t pf_line = 0;
  const int64_t pf_lines = (K * J * int64_t(sizeof(R)) + 63) / 64;
  const int pf_per_k = blocks > 0 ? static_cast<int>((pf_lines + blocks * K - 1) / (blocks * K)) : 0;
  // The row count as a template constant, so that the accumulators stay in registers.
  using RowsFn = void (*)(const std::complex<R>*, const CView<R>&, std::complex<R>*, int64_t, int64_t, const CView<R>*,
                          int64_t*, int64_t, int);
  static constexpr RowsFn rows_kernel[RB] = {lanes_rows<R, Conj, 1, KD, JD>, lanes_rows<R, Conj, 2, KD, JD>,
                                             lanes_rows<R, Conj, 3, KD, JD>, lanes_rows<R, Conj, 4, KD, JD>,
                                             lanes_rows<R, Conj, 5, KD, JD>, lanes_rows<R, Conj, 6, KD, JD>};
  for (int64_t r0 = 0; r0 < n; r0 += per_pass) {
    const int64_t rows = std::min<int64_t>(per_pass, n - r0);
    const std::complex<R>* ar = a + r0 * K;
    std::complex<R>* dr = dst + r0 * J;
    rows_kernel[rows - 1](ar, M, dr, K, J, next, &pf_line, pf_lines, pf_per_k);
    for (int64_t j = J / L * L; j < J; ++j)  // columns beyond the whole packets
      for (int64_t r = 0; r < rows; ++r) {
        std::complex<R> acc(0);
        for (int64_t k = 0; k < K; ++k) {
          const std::complex<R> m(M.re[k * J + j], M.im[k * J + j]);
          acc += ar[r * K + k] * (Conj ? std::conj(m) : m);
        }
        dr[r * J + j] += acc;
      }
  }
}

template <class R, bool Conj> void lanes_product(const std::complex<R>* a, const CView<R>& M, std::complex<R>* dst,
                                                 int64_t n, int64_t K, int64_t J, const CView<R>* next = nullptr) {
  if (K == 64 && J == 64)  // the field's hidden layers
    lanes_product_impl<R, Conj, 64, 64>(a, M, dst, n, K, J, next);
  else
    lanes_product_impl<R, Conj, 0, 0>(a, M, dst, n, K, J, next);
}

// dx[n x in] += g[n x out] conj(W) for one group.
template <class R> void backward_x(const std::complex<R>* g, const CView<R>& W, std::complex<R>* dx, int64_t n,
                                   int64_t in, int64_t out, const CView<R>* next = nullptr) {
  lanes_product<R, true>(g, W, dx, n, out, in, next);
}

// The planes of W [out x in] transposed into t_re, t_im [in x out]: L x L tiles through
// registers, the ragged edges element by element.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wignored-attributes"  // PacketBlock of an SIMD type, as Eigen's own code has
template <class R> void transpose_planes(const CView<R>& W, int64_t out, int64_t in, Buffer<R>& t_re, Buffer<R>& t_im) {
  using namespace Eigen::internal;
  using P = Packet<R>;
  constexpr int L = kLanes<R>;
  t_re.resize(static_cast<size_t>(in * out));
  t_im.resize(t_re.size());
  const int64_t ot = out / L * L, it = in / L * L;
  for (int plane = 0; plane < 2; ++plane) {
    const R* src = plane == 0 ? W.re : W.im;
    R* dst = plane == 0 ? t_re.data() : t_im.data();
    for (int64_t o = 0; o < ot; o += L)
      for (int64_t i = 0; i < it; i += L) {
        PacketBlock<P, L> b;
        for (int l = 0; l < L; ++l) b.packet[l] = ploadu<P>(src + (o + l) * in + i);
        ptranspose(b);
        for (int l = 0; l < L; ++l) pstoreu(dst + (i + l) * out + o, b.packet[l]);
      }
    for (int64_t o = 0; o < out; ++o)
      for (int64_t i = o < ot ? it : 0; i < in; ++i) dst[i * out + o] = src[o * in + i];
  }
}
#pragma GCC diagnostic pop

// y[n x out] += x W^T for one group (y holds the bias or zeros on entry): W transposed into
// scratch once, then the outputs in the lanes.
template <class R> void forward(const std::complex<R>* x, const CView<R>& W, std::complex<R>* y, int64_t n, int64_t in,
                                int64_t out, Buffer<R>& t_re, Buffer<R>& t_im, const CView<R>* next = nullptr) {
  transpose_planes(W, out, in, t_re, t_im);
  lanes_product<R, false>(x, CView<R>{t_re.data(), t_im.data(), 1}, y, n, in, out, next);
}

// dW[out x in] += g^T conj(x) for one group of n rows, dW as planes: O outputs x Q packets
// of inputs per block, each dW element loaded and stored once. `next` (or null): the next
// group's dW, prefetched for writing meanwhile, a share per block.
template <class R> void backward_w(const std::complex<R>* g, const std::complex<R>* x, const View<R>& dW, int64_t n,
                                   int64_t in, int64_t out, Buffer<R>& xr, Buffer<R>& xi, Buffer<R>& nxi,
                                   const View<R>* next = nullptr, bool overwrite = false) {
  using namespace Eigen::internal;
  using P = Packet<R>;
  constexpr int L = kLanes<R>, O = 2, Q = 4;
  split_planes(x, n, in, xr, xi, nxi);
  const R* gv = reinterpret_cast<const R*>(g);
  const int64_t pf_lines = (in * out * int64_t(sizeof(R)) + 63) / 64;
  const int64_t pf_per_block = (pf_lines + (out / O) - 1) / std::max<int64_t>(1, out / O);
  int64_t pf_line = 0;
  auto block = [&](auto o_count, auto q_count, int64_t o, int64_t i) {
    constexpr int OC = decltype(o_count)::value, QC = decltype(q_count)::value;
    if (next && i == 0)
      for (int64_t l = 0; l < pf_per_block && pf_line < pf_lines; ++l, ++pf_line) {
        __builtin_prefetch(reinterpret_cast<const char*>(next->re) + 64 * pf_line, 1);
        __builtin_prefetch(reinterpret_cast<const char*>(next->im) + 64 * pf_line, 1);
      }
    P re[OC][QC], im[OC][QC];
    for (int j = 0; j < OC; ++j)
      for (int q = 0; q < QC; ++q)
        if (overwrite) {
          re[j][q] = im[j][q] = pset1<P>(R(0));
        } else {
          re[j][q] = ploadu<P>(dW.re + (o + j) * in + i + q * L);
          im[j][q] = ploadu<P>(dW.im + (o + j) * in + i + q * L);
        }
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
      R& dr = dW.re[oo * in + k];
      R& di = dW.im[oo * in + k];
      dr = (overwrite ? R(0) : dr) + acc.real();
      di = (overwrite ? R(0) : di) + acc.imag();
    }
}

}  // namespace ag::grouped_planes_kernel

// Internal to ops_grouped.cpp: SIMD kernels of the complex grouped linear map for one group
// of a few rows (the hyper-network field: ~6 rows per triangle, 64 x 64 complex weights).
//
// A general GEMM per group spends more time packing the 64 x 64 weight block than
// multiplying it with ~6 rows; these kernels read each weight once, straight from its
// row-major (out x in) storage, and put the group's ROWS into the SIMD lanes instead:
// one packet of L reals holds H = L/2 rows, real parts in lanes [0, H) and imaginary
// parts in lanes [H, L). A complex weight w is then applied to H rows with two
// broadcasts and two fused multiply-adds:
//   [re | im](w x) = wr * [xr | xi] + wi * [-xi | xr].
// The packet type is Eigen's for the build's instruction set (SSE, AVX, AVX-512).
// Results equal the plain complex sums up to floating-point rounding order.
// Used for weights stored interleaved (grouped_linear on complex tensors); weights stored as
// two real planes (the model's field) go through grouped_planes_kernel.hpp instead.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <complex>
#include <cstdint>
#include <vector>

namespace ag::grouped_kernel {

template <class R> using Packet = typename Eigen::internal::packet_traits<R>::type;
template <class R> inline constexpr int kLanes = Eigen::internal::unpacket_traits<Packet<R>>::size;
template <class R> using Buffer = std::vector<R, Eigen::aligned_allocator<R>>;

// A complex matrix (row-major, out x in) stored either interleaved (std::complex: es = 2,
// im = re + 1) or as two real planes (es = 1): element e is (re[e * es], im[e * es]).
template <class R> struct CView {
  const R* re;
  const R* im;
  int64_t es;
};
template <class R> struct View {
  R* re;
  R* im;
  int64_t es;
};
template <class R> CView<R> interleaved(const std::complex<R>* W) {
  const R* p = reinterpret_cast<const R*>(W);
  return {p, p + 1, 2};
}
template <class R> View<R> interleaved(std::complex<R>* W) {
  R* p = reinterpret_cast<R*>(W);
  return {p, p + 1, 2};
}

// Rows r0 .. r0+h of the row-major complex matrix `src` (width w) as packets:
// a[k] = [re | im] of column k, s[k] = [sa*im | sb*re] (sa, sb = +-1).
template <class R>
void pack_rows(const std::complex<R>* src, int64_t w, int64_t h, R sa, R sb, Buffer<R>& a, Buffer<R>& s) {
  constexpr int L = kLanes<R>, H = L / 2;
  a.assign(static_cast<size_t>(w * L), R(0));
  s.assign(static_cast<size_t>(w * L), R(0));
  for (int64_t r = 0; r < h; ++r)
    for (int64_t k = 0; k < w; ++k) {
      const std::complex<R> v = src[r * w + k];
      a[k * L + r] = v.real();
      a[k * L + H + r] = v.imag();
      s[k * L + r] = sa * v.imag();
      s[k * L + H + r] = sb * v.real();
    }
}

// acc[j] += sum_k M(j, k) * packed row k, for J outputs at once, where M(j, k) is the complex
// weight number j * sj + k * sk of w and packed rows are (a, s).
// The wr and wi terms go to separate chains (2J independent FMAs per k hide their latency).
template <class R, int J>
inline void accumulate(const CView<R>& w, int64_t sj, int64_t sk, int64_t K, const R* a, const R* s, Packet<R>* acc) {
  using namespace Eigen::internal;
  constexpr int L = kLanes<R>;
  Packet<R> acc1[J], acc2[J];  // locals (not *acc) so that they stay in registers
  for (int j = 0; j < J; ++j) acc1[j] = acc2[j] = pset1<Packet<R>>(R(0));
  const int64_t es = w.es;
  for (int64_t k = 0; k < K; ++k) {
    const Packet<R> pa = pload<Packet<R>>(a + k * L), ps = pload<Packet<R>>(s + k * L);
    for (int j = 0; j < J; ++j) {
      const int64_t e = (j * sj + k * sk) * es;
      acc1[j] = pmadd(pset1<Packet<R>>(w.re[e]), pa, acc1[j]);
      acc2[j] = pmadd(pset1<Packet<R>>(w.im[e]), ps, acc2[j]);
    }
  }
  for (int j = 0; j < J; ++j) acc[j] = padd(acc[j], padd(acc1[j], acc2[j]));
}

// The view advanced by e elements.
template <class R> CView<R> shift(const CView<R>& w, int64_t e) { return {w.re + e * w.es, w.im + e * w.es, w.es}; }

// Prefetches part `b` of `parts` of the bytes [p, p + bytes) (the next group's weights,
// spread over the blocks of the current group so that DRAM latency hides behind work).
inline void prefetch_part(const void* p, int64_t bytes, int64_t b, int64_t parts) {
  if (!p) return;
  const int64_t lines = (bytes + 63) / 64, per = (lines + parts - 1) / parts;
  const char* c = static_cast<const char*>(p);
  for (int64_t l = b * per; l < std::min(lines, (b + 1) * per); ++l) __builtin_prefetch(c + 64 * l);
}
// The same for a view of `count` complex elements (one region, or two planes).
template <class R> void prefetch_part(const CView<R>* v, int64_t count, int64_t b, int64_t parts) {
  if (!v) return;
  const int64_t bytes = count * v->es * int64_t(sizeof(R));
  prefetch_part(v->re, bytes, b, parts);
  if (v->es == 1) prefetch_part(v->im, bytes, b, parts);
}

// Adds packet acc (rows in lanes) to column c of the h rows at dst (width w).
template <class R> inline void unpack_add(const Packet<R>& acc, std::complex<R>* dst, int64_t w, int64_t c, int64_t h) {
  constexpr int L = kLanes<R>, H = L / 2;
  alignas(64) R t[L];
  Eigen::internal::pstore(t, acc);
  for (int64_t r = 0; r < h; ++r) dst[r * w + c] += std::complex<R>(t[r], t[H + r]);
}

// y[n x out] += x[n x in] W^T for one group (W row-major out x in). y must hold the bias
// (or zeros) on entry. Scratch buffers a, s are reused across calls; `next` (or null) is the
// next group's W, prefetched meanwhile.
template <class R> void forward(const std::complex<R>* x, const CView<R>& W, std::complex<R>* y, int64_t n, int64_t in,
                                int64_t out, Buffer<R>& a, Buffer<R>& s, const CView<R>* next = nullptr) {
  using namespace Eigen::internal;
  constexpr int L = kLanes<R>, H = L / 2, J = 4;
  const int64_t wcount = in * out, blocks = (out + J - 1) / J;
  for (int64_t r0 = 0; r0 < n; r0 += H) {
    const int64_t h = std::min<int64_t>(H, n - r0);
    pack_rows<R>(x + r0 * in, in, h, R(-1), R(1), a, s);  // [xr|xi], [-xi|xr]
    int64_t o = 0;
    for (; o + J <= out; o += J) {
      if (r0 == 0) prefetch_part(next, wcount, o / J, blocks);
      Packet<R> acc[J];
      for (auto& p : acc) p = pset1<Packet<R>>(R(0));
      accumulate<R, J>(shift(W, o * in), in, 1, in, a.data(), s.data(), acc);
      for (int j = 0; j < J; ++j) unpack_add<R>(acc[j], y + r0 * out, out, o + j, h);
    }
    for (; o < out; ++o) {
      if (r0 == 0) prefetch_part(next, wcount, o / J, blocks);
      Packet<R> acc[1] = {pset1<Packet<R>>(R(0))};
      accumulate<R, 1>(shift(W, o * in), in, 1, in, a.data(), s.data(), acc);
      unpack_add<R>(acc[0], y + r0 * out, out, o, h);
    }
  }
}

// dx[n x in] += g[n x out] conj(W) for one group (W read by column blocks of J: with
// complex<float>, one 64-byte line per W row and block).
template <class R> void backward_x(const std::complex<R>* g, const CView<R>& W, std::complex<R>* dx, int64_t n,
                                   int64_t in, int64_t out, Buffer<R>& a, Buffer<R>& s,
                                   const CView<R>* next = nullptr) {
  using namespace Eigen::internal;
  constexpr int L = kLanes<R>, H = L / 2, J = 8;
  const int64_t wcount = in * out, blocks = (in + J - 1) / J;
  for (int64_t r0 = 0; r0 < n; r0 += H) {
    const int64_t h = std::min<int64_t>(H, n - r0);
    // conj(w) g: re = wr gr + wi gi, im = wr gi - wi gr  ->  s = [gi | -gr].
    pack_rows<R>(g + r0 * out, out, h, R(1), R(-1), a, s);
    int64_t i = 0;
    for (; i + J <= in; i += J) {
      if (r0 == 0) prefetch_part(next, wcount, i / J, blocks);
      Packet<R> acc[J];
      for (auto& p : acc) p = pset1<Packet<R>>(R(0));
      accumulate<R, J>(shift(W, i), 1, in, out, a.data(), s.data(), acc);
      for (int j = 0; j < J; ++j) unpack_add<R>(acc[j], dx + r0 * in, in, i + j, h);
    }
    for (; i < in; ++i) {
      if (r0 == 0) prefetch_part(next, wcount, i / J, blocks);
      Packet<R> acc[1] = {pset1<Packet<R>>(R(0))};
      accumulate<R, 1>(shift(W, i), 1, in, out, a.data(), s.data(), acc);
      unpack_add<R>(acc[0], dx + r0 * in, in, i, h);
    }
  }
}

// dW[out x in] += g^T conj(x) for one group of n rows: vectorised along W's rows (in), the
// rows' conj(x) interleaved as stored: gy conj(x) = gr [xr, -xi] + gi [xi, xr].
template <class R> void backward_w(const std::complex<R>* g, const std::complex<R>* x, const View<R>& dW, int64_t n,
                                   int64_t in, int64_t out, Buffer<R>& a, Buffer<R>& s) {
  using namespace Eigen::internal;
  constexpr int L = kLanes<R>, C = L / 2;  // C complex numbers per packet
  constexpr int O = 2, Q = 4;              // outputs x packets held in registers
  const int64_t np = in / C;               // whole packets per row; the rest is done in scalars
  a.resize(static_cast<size_t>(n * np * L));
  s.resize(static_cast<size_t>(n * np * L));
  for (int64_t r = 0; r < n; ++r)
    for (int64_t k = 0; k < np * C; ++k) {
      const std::complex<R> v = x[r * in + k];
      R* pa = a.data() + r * np * L + 2 * k;
      R* ps = s.data() + r * np * L + 2 * k;
      pa[0] = v.real(), pa[1] = -v.imag(), ps[0] = v.imag(), ps[1] = v.real();
    }
  const R* gr = reinterpret_cast<const R*>(g);
  auto block = [&](auto o_count, auto q_count, int64_t o, int64_t p) {
    constexpr int OC = decltype(o_count)::value, QC = decltype(q_count)::value;
    Packet<R> acc[OC][QC];
    for (auto& row : acc)
      for (auto& v : row) v = pset1<Packet<R>>(R(0));
    for (int64_t r = 0; r < n; ++r) {
      const R* ar = a.data() + (r * np + p) * L;
      const R* sr = s.data() + (r * np + p) * L;
      for (int j = 0; j < OC; ++j) {
        const Packet<R> re = pset1<Packet<R>>(gr[2 * (r * out + o + j)]);
        const Packet<R> im = pset1<Packet<R>>(gr[2 * (r * out + o + j) + 1]);
        for (int q = 0; q < QC; ++q)
          acc[j][q] = pmadd(re, pload<Packet<R>>(ar + q * L), pmadd(im, pload<Packet<R>>(sr + q * L), acc[j][q]));
      }
    }
    for (int j = 0; j < OC; ++j)
      for (int q = 0; q < QC; ++q) {
        const int64_t e = (o + j) * in + (p + q) * C;  // first element of the packet
        if (dW.es == 2) {                              // interleaved like the packet
          R* d = dW.re + 2 * e;
          pstoreu(d, padd(ploadu<Packet<R>>(d), acc[j][q]));
        } else {
          alignas(64) R t[L];
          pstore(t, acc[j][q]);
          for (int m = 0; m < C; ++m) dW.re[e + m] += t[2 * m], dW.im[e + m] += t[2 * m + 1];
        }
      }
  };
  using I1 = std::integral_constant<int, 1>;
  using IO = std::integral_constant<int, O>;
  using IQ = std::integral_constant<int, Q>;
  int64_t o = 0;
  for (; o + O <= out; o += O) {
    int64_t p = 0;
    for (; p + Q <= np; p += Q) block(IO{}, IQ{}, o, p);
    for (; p < np; ++p) block(IO{}, I1{}, o, p);
  }
  for (; o < out; ++o) {
    int64_t p = 0;
    for (; p + Q <= np; p += Q) block(I1{}, IQ{}, o, p);
    for (; p < np; ++p) block(I1{}, I1{}, o, p);
  }
  for (int64_t k = np * C; k < in; ++k)  // columns beyond the whole packets
    for (int64_t oo = 0; oo < out; ++oo) {
      std::complex<R> acc(0);
      for (int64_t r = 0; r < n; ++r) acc += g[r * out + oo] * std::conj(x[r * in + k]);
      dW.re[(oo * in + k) * dW.es] += acc.real();
      dW.im[(oo * in + k) * dW.es] += acc.imag();
    }
}

}  // namespace ag::grouped_kernel

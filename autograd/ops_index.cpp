#include "autograd/ops_index.hpp"

#include <algorithm>
#include <string>

namespace ag {
namespace {

template <class T> T conj_if(const T& v) {
  if constexpr (is_complex_v<T>)
    return std::conj(v);
  else
    return v;
}

void check_index(const char* op, const Index& index, int64_t bound, const Shape& x_shape) {
  for (size_t i = 0; i < index.size(); ++i)
    if (index[i] < 0 || index[i] >= bound)
      throw Error(std::string(op) + ": index " + std::to_string(index[i]) + " at position " + std::to_string(i) +
                  " outside [0, " + std::to_string(bound) + ") for " + shape_str(x_shape));
}

// Receivers of a scatter in compressed-row form: the positions p of `index` with
// index[p] == r are pos[offset[r] .. offset[r+1]), in increasing p (a stable counting sort).
// Summing each receiver's sources in that order gives the serial loop's result bit for bit,
// whatever the number of threads: every output row is owned by one thread.
struct Csr {
  std::vector<int64_t> offset, pos;
};

Csr make_csr(const Index& index, int64_t num_rows) {
  Csr c;
  c.offset.assign(static_cast<size_t>(num_rows + 1), 0);
  for (int64_t r : index) ++c.offset[r + 1];
  for (int64_t r = 0; r < num_rows; ++r) c.offset[r + 1] += c.offset[r];
  c.pos.resize(index.size());
  std::vector<int64_t> next(c.offset.begin(), c.offset.end() - 1);
  for (size_t p = 0; p < index.size(); ++p) c.pos[next[index[p]]++] = static_cast<int64_t>(p);
  return c;
}

// dst[index[p]] += src[p] (rows of width C) as a segment sum: parallel over receivers,
// deterministic. `scale`, if given, multiplies each receiver's row afterwards (scatter_mean;
// dst must then start at 0). overwrite: dst's old values are not read; each row becomes its
// sum (0 where nothing points), so a first gradient needs no zero fill beforehand.
template <class T> void scatter_add_csr(T* dst, const T* src, const Index& index, int64_t num_rows, int64_t C,
                                        const real_t<T>* scale = nullptr, bool overwrite = false) {
  if (index.empty()) {
    if (overwrite) std::fill(dst, dst + num_rows * C, T(0));
    return;
  }
  const Csr c = make_csr(index, num_rows);
  const int64_t n = static_cast<int64_t>(index.size());
#pragma omp parallel for schedule(static) if (n * C > kParallelMin)
  for (int64_t r = 0; r < num_rows; ++r) {
    int64_t b = c.offset[r];
    const int64_t e = c.offset[r + 1];
    T* d = dst + r * C;
    if (b == e) {  // nothing points here
      if (overwrite) std::fill(d, d + C, T(0));
      continue;
    }
    if (overwrite) {  // the first source is copied, the others added
      std::copy(src + c.pos[b] * C, src + (c.pos[b] + 1) * C, d);
      ++b;
    }
    for (int64_t k = b; k < e; ++k) {
      const T* s = src + c.pos[k] * C;
      for (int64_t j = 0; j < C; ++j) d[j] += s[j];
    }
    if (scale)
      for (int64_t j = 0; j < C; ++j) d[j] *= scale[r];
  }
}

}  // namespace

// ---- index_select_rows (gather) -------------------------------------------------------------
template <class T> Tensor<T> index_select_rows(const Tensor<T>& x, const Index& index) {
  check_2d("index_select_rows", x.shape());
  const int64_t R = x.rows(), C = x.cols(), N = static_cast<int64_t>(index.size());
  check_index("index_select_rows", index, R, x.shape());
  auto out = new_output_overwritten<T>({N, C});
  const T* s = x.data();
  T* o = out.data();
#pragma omp parallel for if (N * C > kParallelMin)
  for (int64_t i = 0; i < N; ++i) std::copy(s + index[i] * C, s + (index[i] + 1) * C, o + i * C);
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), index, C] {
    if (!xn->requires_grad) return;
    const bool first = xn->claim_whole_grad();
    scatter_add_csr(xn->grad.data(), on->grad.data(), index, xn->shape[0], C, nullptr, first);
  });
  return out;
}

// ---- add_gathered_rows (an edge's input in message passing) -----------------------------------
template <class T> Tensor<T> add_gathered_rows(const Tensor<T>& base, const Tensor<T>& a, const Index& ia,
                                               const Tensor<T>& b, const Index& ib) {
  check_2d("add_gathered_rows", base.shape());
  check_2d("add_gathered_rows", a.shape());
  check_2d("add_gathered_rows", b.shape());
  const int64_t N = base.rows(), C = base.cols();
  if (a.cols() != C || b.cols() != C)
    throw Error("add_gathered_rows: widths differ, base " + shape_str(base.shape()) + ", a " + shape_str(a.shape()) +
                ", b " + shape_str(b.shape()));
  if (static_cast<int64_t>(ia.size()) != N || static_cast<int64_t>(ib.size()) != N)
    throw Error("add_gathered_rows: " + std::to_string(ia.size()) + " and " + std::to_string(ib.size()) +
                " indices for " + std::to_string(N) + " rows of base");
  check_index("add_gathered_rows", ia, a.rows(), a.shape());
  check_index("add_gathered_rows", ib, b.rows(), b.shape());
  auto out = new_output_overwritten<T>({N, C});
  const T *x = base.data(), *pa = a.data(), *pb = b.data();
  T* o = out.data();
#pragma omp parallel for if (N * C > kParallelMin)
  for (int64_t i = 0; i < N; ++i) {
    const T *xr = x + i * C, *ar = pa + ia[i] * C, *br = pb + ib[i] * C;
    T* orow = o + i * C;
    for (int64_t j = 0; j < C; ++j) orow[j] = xr[j] + (ar[j] + br[j]);
  }
  record(out.node(), {base.node_ptr(), a.node_ptr(), b.node_ptr()},
         [xn = &base.node(), an = &a.node(), bn = &b.node(), on = &out.node(), ia, ib, C] {
           const T* g = on->grad.data();
           for (auto [pn, index] : {std::pair{an, &ia}, std::pair{bn, &ib}}) {
             if (!pn->requires_grad) continue;
             const bool first = pn->claim_whole_grad();
             scatter_add_csr(pn->grad.data(), g, *index, pn->shape[0], C, nullptr, first);
           }
           // base's gradient is g itself: last, since it may take over g's buffer.
           if (!xn->requires_grad || xn->take_grad(*on)) return;
           const bool first = xn->claim_whole_grad();
           T* gx = xn->grad.data();
           const int64_t N = xn->shape[0];
#pragma omp parallel for if (N * C > kParallelMin)
           for (int64_t i = 0; i < N; ++i) write_or_add(gx + i * C, g + i * C, C, first);
         });
  return out;
}

// Shared checks of the scatter ops: x 2-D, one index per row, indices in [0, num_rows).
static void check_scatter(const char* op, const Shape& xs, const Index& index, int64_t num_rows) {
  check_2d(op, xs);
  if (static_cast<int64_t>(index.size()) != xs[0])
    throw Error(std::string(op) + ": " + std::to_string(index.size()) + " indices for " + shape_str(xs));
  if (num_rows < 0) throw Error(std::string(op) + ": negative num_rows");
  check_index(op, index, num_rows, xs);
}

// ---- scatter_add_rows (segment sum) -----------------------------------------------------------
template <class T> Tensor<T> scatter_add_rows(const Tensor<T>& x, const Index& index, int64_t num_rows) {
  check_scatter("scatter_add_rows", x.shape(), index, num_rows);
  const int64_t N = x.rows(), C = x.cols();
  auto out = new_output_overwritten<T>({num_rows, C});  // each row its sum, or 0
  scatter_add_csr(out.data(), x.data(), index, num_rows, C, nullptr, true);
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), index, C, N] {
    if (!xn->requires_grad) return;
    const bool first = xn->claim_whole_grad();
    T* g = xn->grad.data();
    const T* go = on->grad.data();
#pragma omp parallel for if (N * C > kParallelMin)
    for (int64_t i = 0; i < N; ++i) {
      write_or_add(g + i * C, go + index[i] * C, C, first);
    }
  });
  return out;
}

// ---- scatter_mean_rows --------------------------------------------------------------------------
template <class T> Tensor<T> scatter_mean_rows(const Tensor<T>& x, const Index& index, int64_t num_rows) {
  check_scatter("scatter_mean_rows", x.shape(), index, num_rows);
  const int64_t N = x.rows(), C = x.cols();
  std::vector<real_t<T>> inv(static_cast<size_t>(num_rows), 0);
  for (int64_t i : index) inv[i] += 1;
  for (auto& v : inv) v = v > 0 ? real_t<T>(1) / v : real_t<T>(0);
  auto out = new_output<T>({num_rows, C});
  scatter_add_csr(out.data(), x.data(), index, num_rows, C, inv.data());
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), index, inv, C, N] {
    if (!xn->requires_grad) return;
    xn->ensure_grad();
    T* g = xn->grad.data();
    const T* go = on->grad.data();
#pragma omp parallel for if (N * C > kParallelMin)
    for (int64_t i = 0; i < N; ++i) {
      const T* s = go + index[i] * C;
      const real_t<T> w = inv[index[i]];
      for (int64_t j = 0; j < C; ++j) g[i * C + j] += w * s[j];
    }
  });
  return out;
}

// ---- interpolate_rows ---------------------------------------------------------------------------
template <class T> Tensor<T> interpolate_rows(const Tensor<T>& x, const Index& index, const Tensor<T>& weight) {
  check_2d("interpolate_rows", x.shape());
  check_2d("interpolate_rows", weight.shape());
  const int64_t R = x.rows(), C = x.cols(), N = weight.rows(), K = weight.cols();
  if (static_cast<int64_t>(index.size()) != N * K)
    throw Error("interpolate_rows: " + std::to_string(index.size()) + " indices for weight " +
                shape_str(weight.shape()) + " (need rows*cols)");
  check_index("interpolate_rows", index, R, x.shape());
  auto out = new_output<T>({N, C});
  const T* xs = x.data();
  const T* w = weight.data();
  T* o = out.data();
#pragma omp parallel for if (N * K * C > kParallelMin)
  for (int64_t i = 0; i < N; ++i) {
    T* oi = o + i * C;
    for (int64_t k = 0; k < K; ++k) {
      const T wk = w[i * K + k];
      const T* s = xs + index[i * K + k] * C;
      for (int64_t j = 0; j < C; ++j) oi[j] += wk * s[j];
    }
  }
  record(out.node(), {x.node_ptr(), weight.node_ptr()},
         [xn = &x.node(), wn = &weight.node(), on = &out.node(), index, N, K, C] {
           const T* go = on->grad.data();
           if (wn->requires_grad) {
             wn->ensure_grad();
             const T* xs = xn->value.data();
             T* gw = wn->grad.data();
      // d/dw[i,k] = <x[idx], g[i]> (conjugated on x for complex: grad = conj(x) g).
#pragma omp parallel for if (N * K * C > kParallelMin)
             for (int64_t i = 0; i < N; ++i)
               for (int64_t k = 0; k < K; ++k) {
                 const T* s = xs + index[i * K + k] * C;
                 T acc(0);
                 for (int64_t j = 0; j < C; ++j) acc += conj_if(s[j]) * go[i * C + j];
                 gw[i * K + k] += acc;
               }
           }
           if (xn->requires_grad) {
             xn->ensure_grad();
             const T* w = wn->value.data();
             T* gx = xn->grad.data();
             // Segment sum over the receivers x[index[p]], p = i*K + k (as scatter_add_csr).
             const int64_t R = xn->shape[0];
             const Csr c = make_csr(index, R);
#pragma omp parallel for schedule(static) if (N * K * C > kParallelMin)
             for (int64_t r = 0; r < R; ++r) {
               T* d = gx + r * C;
               for (int64_t q = c.offset[r]; q < c.offset[r + 1]; ++q) {
                 const int64_t p = c.pos[q];
                 const T wk = conj_if(w[p]);
                 const T* g = go + (p / K) * C;
                 for (int64_t j = 0; j < C; ++j) d[j] += wk * g[j];
               }
             }
           }
         });
  return out;
}

#define AG_INSTANTIATE(T)                                                                                     \
  template Tensor<T> index_select_rows<T>(const Tensor<T>&, const Index&);                                    \
  template Tensor<T> scatter_add_rows<T>(const Tensor<T>&, const Index&, int64_t);                            \
  template Tensor<T> scatter_mean_rows<T>(const Tensor<T>&, const Index&, int64_t);                           \
  template Tensor<T> interpolate_rows<T>(const Tensor<T>&, const Index&, const Tensor<T>&);                   \
  template Tensor<T> add_gathered_rows<T>(const Tensor<T>&, const Tensor<T>&, const Index&, const Tensor<T>&, \
                                          const Index&);
AG_INSTANTIATE(float)
AG_INSTANTIATE(double)
AG_INSTANTIATE(std::complex<float>)
AG_INSTANTIATE(std::complex<double>)
#undef AG_INSTANTIATE

}  // namespace ag

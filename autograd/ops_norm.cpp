#include "autograd/ops_norm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace ag {
namespace {

// Column reductions over row blocks of fixed size, combined in block order: deterministic for
// any thread count. add_row(r, acc) folds row r's contribution into acc[0 .. width);
// combine(a, b) merges two block partials (a sum unless told otherwise).
constexpr int64_t kBlock = 512;
struct Plus {
  template <class T> T operator()(T a, T b) const { return a + b; }
};
template <class T, class F, class Combine = Plus>
std::vector<T> column_reduce(int64_t R, int64_t width, int64_t work_per_row, F add_row, Combine combine = {}) {
  const int64_t nb = (R + kBlock - 1) / kBlock;
  std::vector<T> part(static_cast<size_t>(std::max<int64_t>(nb, 1) * width), T(0));
#pragma omp parallel for schedule(static) if (R * work_per_row > kParallelMin)
  for (int64_t b = 0; b < nb; ++b) {
    T* acc = part.data() + b * width;
    const int64_t r1 = std::min(R, (b + 1) * kBlock);
    for (int64_t r = b * kBlock; r < r1; ++r) add_row(r, acc);
  }
  for (int64_t b = 1; b < nb; ++b)
    for (int64_t j = 0; j < width; ++j) part[j] = combine(part[j], part[b * width + j]);
  part.resize(static_cast<size_t>(width));
  return part;
}

// A power of two near the largest magnitude m (1 if m is 0 or not finite): scaling by it is
// exact, so results in the normal range are those of the unscaled formula; its exponent is
// clamped so that its reciprocal is finite too (subnormal rows).
template <class T> T pow2_scale(T m) {
  if (!(m > T(0)) || !std::isfinite(m)) return T(1);
  const int e = std::max(std::ilogb(m), std::numeric_limits<T>::min_exponent - 1);
  return std::ldexp(T(1), std::min(e, std::numeric_limits<T>::max_exponent - 2));
}

// Mean and variance are taken of x / scale (scale from pow2_scale), so that neither the sum
// nor the squares overflow or underflow: float32 rows of size 1e20 would otherwise give
// var = inf and all-zero outputs. With var_s the (biased) variance of x / scale:
//   y = (x / scale - mean(x / scale)) * y_gain,  inv = 1 / sqrt(var(x) + eps) (for backward).
template <class T> struct NormStats {
  T y_gain = 0, inv = 0;
};
template <class T> NormStats<T> norm_stats(T scale, T var_s, T eps) {
  NormStats<T> st;
  if (scale >= T(1)) {  // var(x) + eps = scale^2 (var_s + eps / scale^2)
    const T t = std::sqrt(var_s + eps / scale / scale);
    st.y_gain = T(1) / t;
    st.inv = st.y_gain / scale;
  } else {  // scale^2 var_s may underflow only where eps dominates it
    const T t = std::sqrt(scale * scale * var_s + eps);
    st.inv = T(1) / t;
    st.y_gain = scale / t;
  }
  return st;
}

template <class T> void check_eps(const char* op, T eps) {
  if (!(eps > T(0)) || !std::isfinite(eps))
    throw Error(std::string(op) + ": eps must be finite and > 0 (it keeps equal rows finite), got " +
                std::to_string(eps));
}

}  // namespace

// ---- channel_norm (per column, across rows) ---------------------------------------------------------
template <class T> Tensor<T> channel_norm(const Tensor<T>& x, T eps) {
  check_2d("channel_norm", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  if (R == 0) throw Error("channel_norm: no rows in " + shape_str(x.shape()));
  check_eps("channel_norm", eps);
  const T* px = x.data();
  const std::vector<T> scale = column_reduce<T>(
      R, C, C,
      [px, C](int64_t r, T* acc) {
        const T* xr = px + r * C;
        for (int64_t j = 0; j < C; ++j) acc[j] = std::max(acc[j], std::abs(xr[j]));
      },
      [](T a, T b) { return std::max(a, b); });
  std::vector<T> sc(static_cast<size_t>(C)), isc(static_cast<size_t>(C));
  for (int64_t j = 0; j < C; ++j) {
    sc[j] = pow2_scale(scale[j]);
    isc[j] = T(1) / sc[j];
  }
  std::vector<T> mu = column_reduce<T>(R, C, C, [px, C, &isc](int64_t r, T* acc) {
    const T* xr = px + r * C;
    for (int64_t j = 0; j < C; ++j) acc[j] += xr[j] * isc[j];
  });
  for (auto& m : mu) m /= T(R);
  std::vector<T> var = column_reduce<T>(R, C, C, [px, C, &mu, &isc](int64_t r, T* acc) {
    const T* xr = px + r * C;
    for (int64_t j = 0; j < C; ++j) {
      const T d = xr[j] * isc[j] - mu[j];
      acc[j] += d * d;
    }
  });
  std::vector<T> gain(static_cast<size_t>(C)), inv(static_cast<size_t>(C));
  for (int64_t j = 0; j < C; ++j) {
    const NormStats<T> st = norm_stats(sc[j], var[j] / T(R), eps);
    gain[j] = st.y_gain;
    inv[j] = st.inv;
  }
  auto out = new_output_overwritten<T>({R, C});  // every element written below
  T* o = out.data();
#pragma omp parallel for if (R * C > kParallelMin)
  for (int64_t r = 0; r < R; ++r)
    for (int64_t j = 0; j < C; ++j) o[r * C + j] = (px[r * C + j] * isc[j] - mu[j]) * gain[j];
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), inv, R, C] {
    if (!xn->requires_grad) return;
    const bool first = xn->claim_whole_grad();
    const T* g = on->grad.data();
    const T* y = on->value.data();
    // dx = inv * (g - mean(g) - y * mean(g y)) per column
    std::vector<T> s = column_reduce<T>(R, 2 * C, C, [g, y, C](int64_t r, T* acc) {
      const T* gr = g + r * C;
      const T* yr = y + r * C;
      for (int64_t j = 0; j < C; ++j) {
        acc[j] += gr[j];
        acc[C + j] += gr[j] * yr[j];
      }
    });
    for (auto& v : s) v /= T(R);
    T* gx = xn->grad.data();
#pragma omp parallel for if (R * C > kParallelMin)
    for (int64_t r = 0; r < R; ++r)
      for (int64_t j = 0; j < C; ++j) {
        const int64_t k = r * C + j;
        const T d = inv[j] * (g[k] - s[j] - y[k] * s[C + j]);
        gx[k] = first ? d : gx[k] + d;
      }
  });
  return out;
}

// ---- layer_norm (per row, across columns) ------------------------------------------------------------
template <class T> Tensor<T> layer_norm(const Tensor<T>& x, T eps) {
  check_2d("layer_norm", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  if (C == 0) throw Error("layer_norm: no columns in " + shape_str(x.shape()));
  check_eps("layer_norm", eps);
  auto out = new_output_overwritten<T>({R, C});  // every row written below
  std::vector<T> inv(static_cast<size_t>(R));
  const T* px = x.data();
  T* o = out.data();
#pragma omp parallel for if (R * C > kParallelMin)
  for (int64_t r = 0; r < R; ++r) {
    const T* xr = px + r * C;
    T mx = 0;
    for (int64_t j = 0; j < C; ++j) mx = std::max(mx, std::abs(xr[j]));
    const T s = pow2_scale(mx), is = T(1) / s;
    T m = 0;
    for (int64_t j = 0; j < C; ++j) m += xr[j] * is;
    m /= T(C);
    T v = 0;
    for (int64_t j = 0; j < C; ++j) v += (xr[j] * is - m) * (xr[j] * is - m);
    const NormStats<T> st = norm_stats(s, v / T(C), eps);
    inv[r] = st.inv;
    for (int64_t j = 0; j < C; ++j) o[r * C + j] = (xr[j] * is - m) * st.y_gain;
  }
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), inv = std::move(inv), R, C] {
    if (!xn->requires_grad) return;
    const bool first = xn->claim_whole_grad();
    const T* g = on->grad.data();
    const T* y = on->value.data();
    T* gx = xn->grad.data();
#pragma omp parallel for if (R * C > kParallelMin)
    for (int64_t r = 0; r < R; ++r) {
      const T* gr = g + r * C;
      const T* yr = y + r * C;
      T mg = 0, mgy = 0;
      for (int64_t j = 0; j < C; ++j) {
        mg += gr[j];
        mgy += gr[j] * yr[j];
      }
      mg /= T(C);
      mgy /= T(C);
      for (int64_t j = 0; j < C; ++j) {
        const T d = inv[r] * (gr[j] - mg - yr[j] * mgy);
        gx[r * C + j] = first ? d : gx[r * C + j] + d;
      }
    }
  });
  return out;
}

#define AG_INSTANTIATE(T)                                  \
  template Tensor<T> channel_norm<T>(const Tensor<T>&, T); \
  template Tensor<T> layer_norm<T>(const Tensor<T>&, T);
AG_INSTANTIATE(float)
AG_INSTANTIATE(double)
#undef AG_INSTANTIATE

}  // namespace ag

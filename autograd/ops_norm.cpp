#include "autograd/ops_norm.hpp"

#include <algorithm>
#include <cmath>

namespace ag {
namespace {

// Column sums over row blocks of fixed size, combined in block order: deterministic for
// any thread count. add_row(r, acc) adds row r's contribution into acc[0 .. width).
constexpr int64_t kBlock = 512;
template <class T, class F> std::vector<T> column_reduce(int64_t R, int64_t width, int64_t work_per_row, F add_row) {
  const int64_t nb = (R + kBlock - 1) / kBlock;
  std::vector<T> part(static_cast<size_t>(std::max<int64_t>(nb, 1) * width), T(0));
#pragma omp parallel for schedule(static) if (R * work_per_row > kParallelMin)
  for (int64_t b = 0; b < nb; ++b) {
    T* acc = part.data() + b * width;
    const int64_t r1 = std::min(R, (b + 1) * kBlock);
    for (int64_t r = b * kBlock; r < r1; ++r) add_row(r, acc);
  }
  for (int64_t b = 1; b < nb; ++b)
    for (int64_t j = 0; j < width; ++j) part[j] += part[b * width + j];
  part.resize(static_cast<size_t>(width));
  return part;
}

}  // namespace

// ---- channel_norm (per column, across rows) ---------------------------------------------------------
template <class T> Tensor<T> channel_norm(const Tensor<T>& x, T eps) {
  check_2d("channel_norm", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  if (R == 0) throw Error("channel_norm: no rows in " + shape_str(x.shape()));
  const T* px = x.data();
  std::vector<T> mu = column_reduce<T>(R, C, C, [px, C](int64_t r, T* acc) {
    const T* xr = px + r * C;
    for (int64_t j = 0; j < C; ++j) acc[j] += xr[j];
  });
  for (auto& m : mu) m /= T(R);
  std::vector<T> inv = column_reduce<T>(R, C, C, [px, C, &mu](int64_t r, T* acc) {
    const T* xr = px + r * C;
    for (int64_t j = 0; j < C; ++j) {
      const T d = xr[j] - mu[j];
      acc[j] += d * d;
    }
  });
  for (auto& v : inv) v = T(1) / std::sqrt(v / T(R) + eps);
  auto out = new_output<T>({R, C});
  T* o = out.data();
#pragma omp parallel for if (R * C > kParallelMin)
  for (int64_t r = 0; r < R; ++r)
    for (int64_t j = 0; j < C; ++j) o[r * C + j] = (px[r * C + j] - mu[j]) * inv[j];
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), inv, R, C] {
    if (!xn->requires_grad) return;
    xn->ensure_grad();
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
        gx[k] += inv[j] * (g[k] - s[j] - y[k] * s[C + j]);
      }
  });
  return out;
}

// ---- layer_norm (per row, across columns) ------------------------------------------------------------
template <class T> Tensor<T> layer_norm(const Tensor<T>& x, T eps) {
  check_2d("layer_norm", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  if (C == 0) throw Error("layer_norm: no columns in " + shape_str(x.shape()));
  auto out = new_output<T>({R, C});
  std::vector<T> inv(static_cast<size_t>(R));
  const T* px = x.data();
  T* o = out.data();
#pragma omp parallel for if (R * C > kParallelMin)
  for (int64_t r = 0; r < R; ++r) {
    const T* xr = px + r * C;
    T m = 0;
    for (int64_t j = 0; j < C; ++j) m += xr[j];
    m /= T(C);
    T v = 0;
    for (int64_t j = 0; j < C; ++j) v += (xr[j] - m) * (xr[j] - m);
    inv[r] = T(1) / std::sqrt(v / T(C) + eps);
    for (int64_t j = 0; j < C; ++j) o[r * C + j] = (xr[j] - m) * inv[r];
  }
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), inv = std::move(inv), R, C] {
    if (!xn->requires_grad) return;
    xn->ensure_grad();
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
      for (int64_t j = 0; j < C; ++j) gx[r * C + j] += inv[r] * (gr[j] - mg - yr[j] * mgy);
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

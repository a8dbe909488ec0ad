#include "autograd/ops_vec3.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace ag {

// ---- dot_rows -------------------------------------------------------------------------------------
template <class T> Tensor<T> dot_rows(const Tensor<T>& a, const Tensor<T>& b) {
  check_2d("dot_rows", a.shape());
  check_same_shape("dot_rows", a.shape(), b.shape());
  const int64_t R = a.rows(), C = a.cols();
  auto out = new_output<T>({R, 1});
  const T *pa = a.data(), *pb = b.data();
  T* o = out.data();
#pragma omp parallel for if (R * C > kParallelMin)
  for (int64_t r = 0; r < R; ++r) {
    T s = 0;
    for (int64_t j = 0; j < C; ++j) s += pa[r * C + j] * pb[r * C + j];
    o[r] = s;
  }
  record(out.node(), {a.node_ptr(), b.node_ptr()}, [an = &a.node(), bn = &b.node(), on = &out.node(), R, C] {
    const T* g = on->grad.data();
    // d/da = g b, d/db = g a
    for (auto [xn, yn] : {std::pair{an, bn}, std::pair{bn, an}}) {
      if (!xn->requires_grad) continue;
      xn->ensure_grad();
      T* gx = xn->grad.data();
      const T* y = yn->value.data();
#pragma omp parallel for if (R * C > kParallelMin)
      for (int64_t r = 0; r < R; ++r)
        for (int64_t j = 0; j < C; ++j) gx[r * C + j] += g[r] * y[r * C + j];
    }
  });
  return out;
}

// ---- cross3 -----------------------------------------------------------------------------------------
namespace {
template <class T> inline void cross_add(const T* u, const T* v, T* out) {
  out[0] += u[1] * v[2] - u[2] * v[1];
  out[1] += u[2] * v[0] - u[0] * v[2];
  out[2] += u[0] * v[1] - u[1] * v[0];
}
}  // namespace

template <class T> Tensor<T> cross3(const Tensor<T>& a, const Tensor<T>& b) {
  check_2d("cross3", a.shape());
  check_same_shape("cross3", a.shape(), b.shape());
  if (a.cols() != 3) throw Error("cross3: needs [R x 3], got " + shape_str(a.shape()));
  const int64_t R = a.rows();
  auto out = new_output<T>({R, 3});
  const T *pa = a.data(), *pb = b.data();
  T* o = out.data();
#pragma omp parallel for if (R * 3 > kParallelMin)
  for (int64_t r = 0; r < R; ++r) cross_add(pa + 3 * r, pb + 3 * r, o + 3 * r);
  record(out.node(), {a.node_ptr(), b.node_ptr()}, [an = &a.node(), bn = &b.node(), on = &out.node(), R] {
    const T* g = on->grad.data();
    // L = g . (a x b): dL/da = b x g, dL/db = g x a.
    if (an->requires_grad) {
      an->ensure_grad();
      const T* pb = bn->value.data();
      T* ga = an->grad.data();
#pragma omp parallel for if (R * 3 > kParallelMin)
      for (int64_t r = 0; r < R; ++r) cross_add(pb + 3 * r, g + 3 * r, ga + 3 * r);
    }
    if (bn->requires_grad) {
      bn->ensure_grad();
      const T* pa = an->value.data();
      T* gb = bn->grad.data();
#pragma omp parallel for if (R * 3 > kParallelMin)
      for (int64_t r = 0; r < R; ++r) cross_add(g + 3 * r, pa + 3 * r, gb + 3 * r);
    }
  });
  return out;
}

// ---- norm_rows ----------------------------------------------------------------------------------------
namespace {
// A row scaled by a power of two near its largest magnitude (exact), so that its squares
// neither overflow nor underflow: |x| = scale * len, x / |x| = x_j * inv_scale / len.
template <class T> struct ScaledRow {
  T scale = 1, inv_scale = 1, len = 0;  // len = |x / scale|, 0 for the zero row
  T norm() const { return scale * len; }
};
template <class T> ScaledRow<T> scaled_row(const T* x, int64_t C) {
  T m = 0;
  for (int64_t j = 0; j < C; ++j) m = std::max(m, std::abs(x[j]));
  ScaledRow<T> r;
  if (m == 0) return r;
  if (!std::isfinite(m)) {  // inf or NaN entries: plain arithmetic propagates them
    r.len = m;
    return r;
  }
  // clamped so that 1 / scale is finite for subnormal rows
  const int e = std::max(std::ilogb(m), std::numeric_limits<T>::min_exponent - 1);
  r.scale = std::ldexp(T(1), std::min(e, std::numeric_limits<T>::max_exponent - 2));
  r.inv_scale = T(1) / r.scale;
  T s = 0;
  for (int64_t j = 0; j < C; ++j) {
    const T v = x[j] * r.inv_scale;
    s += v * v;
  }
  r.len = std::sqrt(s);
  return r;
}
}  // namespace

template <class T> Tensor<T> norm_rows(const Tensor<T>& x) {
  check_2d("norm_rows", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  auto out = new_output<T>({R, 1});
  const T* px = x.data();
  T* o = out.data();
#pragma omp parallel for if (R * C > kParallelMin)
  for (int64_t r = 0; r < R; ++r) o[r] = scaled_row(px + r * C, C).norm();
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), R, C] {
    if (!xn->requires_grad) return;
    xn->ensure_grad();
    const T* g = on->grad.data();
    const T* px = xn->value.data();
    T* gx = xn->grad.data();
#pragma omp parallel for if (R * C > kParallelMin)
    for (int64_t r = 0; r < R; ++r) {
      const ScaledRow<T> sr = scaled_row(px + r * C, C);
      if (sr.len == 0) continue;  // subgradient 0 at the zero vector
      // d|x|/dx = x / |x| = (x / scale) / len: every factor <= 1, finite for subnormal and huge rows
      const T il = T(1) / sr.len;
      for (int64_t j = 0; j < C; ++j) gx[r * C + j] += g[r] * (px[r * C + j] * sr.inv_scale * il);
    }
  });
  return out;
}

// ---- normalize_rows --------------------------------------------------------------------------------------
template <class T> Tensor<T> normalize_rows(const Tensor<T>& x, T eps) {
  check_2d("normalize_rows", x.shape());
  if (!(eps > T(0)) || !std::isfinite(eps))
    throw Error("normalize_rows: eps must be finite and > 0 (it keeps zero rows finite), got " + std::to_string(eps));
  const int64_t R = x.rows(), C = x.cols();
  auto out = new_output<T>({R, C});
  std::vector<ScaledRow<T>> rows(static_cast<size_t>(R));
  const T* px = x.data();
  T* o = out.data();
#pragma omp parallel for if (R * C > kParallelMin)
  for (int64_t r = 0; r < R; ++r) {
    const ScaledRow<T> sr = rows[r] = scaled_row(px + r * C, C);
    if (sr.len > 0 && sr.norm() > eps) {  // x / |x| from the scaled row: finite at any magnitude
      const T il = T(1) / sr.len;
      for (int64_t j = 0; j < C; ++j) o[r * C + j] = px[r * C + j] * sr.inv_scale * il;
    } else {
      for (int64_t j = 0; j < C; ++j) o[r * C + j] = px[r * C + j] / eps;
    }
  }
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), rows = std::move(rows), eps, R, C] {
    if (!xn->requires_grad) return;
    xn->ensure_grad();
    const T* g = on->grad.data();
    const T* y = on->value.data();
    T* gx = xn->grad.data();
#pragma omp parallel for if (R * C > kParallelMin)
    for (int64_t r = 0; r < R; ++r) {
      const T* gr = g + r * C;
      T* gxr = gx + r * C;
      const ScaledRow<T>& sr = rows[r];
      if (sr.len > 0 && sr.norm() > eps) {  // y = x/|x|: dx = (g - y (y.g)) / |x|
        const T* yr = y + r * C;
        T yg = 0;
        for (int64_t j = 0; j < C; ++j) yg += yr[j] * gr[j];
        for (int64_t j = 0; j < C; ++j) gxr[j] += (gr[j] - yr[j] * yg) * sr.inv_scale / sr.len;
      } else {  // y = x/eps
        for (int64_t j = 0; j < C; ++j) gxr[j] += gr[j] / eps;
      }
    }
  });
  return out;
}

#define AG_INSTANTIATE(T)                                             \
  template Tensor<T> dot_rows<T>(const Tensor<T>&, const Tensor<T>&); \
  template Tensor<T> cross3<T>(const Tensor<T>&, const Tensor<T>&);   \
  template Tensor<T> norm_rows<T>(const Tensor<T>&);                  \
  template Tensor<T> normalize_rows<T>(const Tensor<T>&, T);
AG_INSTANTIATE(float)
AG_INSTANTIATE(double)
#undef AG_INSTANTIATE

}  // namespace ag

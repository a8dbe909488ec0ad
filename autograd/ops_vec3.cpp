#include "autograd/ops_vec3.hpp"

#include <algorithm>
#include <cmath>

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
// |row| without overflow/underflow of the squares for very large or small entries.
template <class T> T row_norm(const T* x, int64_t C) {
  T m = 0;
  for (int64_t j = 0; j < C; ++j) m = std::max(m, std::abs(x[j]));
  if (m == 0 || !std::isfinite(m)) return m;
  T s = 0;
  for (int64_t j = 0; j < C; ++j) {
    const T v = x[j] / m;
    s += v * v;
  }
  return m * std::sqrt(s);
}
}  // namespace

template <class T> Tensor<T> norm_rows(const Tensor<T>& x) {
  check_2d("norm_rows", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  auto out = new_output<T>({R, 1});
  const T* px = x.data();
  T* o = out.data();
#pragma omp parallel for if (R * C > kParallelMin)
  for (int64_t r = 0; r < R; ++r) o[r] = row_norm(px + r * C, C);
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), R, C] {
    if (!xn->requires_grad) return;
    xn->ensure_grad();
    const T* g = on->grad.data();
    const T* n = on->value.data();
    const T* px = xn->value.data();
    T* gx = xn->grad.data();
#pragma omp parallel for if (R * C > kParallelMin)
    for (int64_t r = 0; r < R; ++r) {
      if (n[r] == 0) continue;  // subgradient 0 at the zero vector
      const T s = g[r] / n[r];
      for (int64_t j = 0; j < C; ++j) gx[r * C + j] += s * px[r * C + j];
    }
  });
  return out;
}

// ---- normalize_rows --------------------------------------------------------------------------------------
template <class T> Tensor<T> normalize_rows(const Tensor<T>& x, T eps) {
  check_2d("normalize_rows", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  auto out = new_output<T>({R, C});
  std::vector<T> nrm(static_cast<size_t>(R));
  const T* px = x.data();
  T* o = out.data();
#pragma omp parallel for if (R * C > kParallelMin)
  for (int64_t r = 0; r < R; ++r) {
    nrm[r] = row_norm(px + r * C, C);
    const T d = std::max(nrm[r], eps);
    for (int64_t j = 0; j < C; ++j) o[r * C + j] = px[r * C + j] / d;
  }
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), nrm = std::move(nrm), eps, R, C] {
    if (!xn->requires_grad) return;
    xn->ensure_grad();
    const T* g = on->grad.data();
    const T* y = on->value.data();
    T* gx = xn->grad.data();
#pragma omp parallel for if (R * C > kParallelMin)
    for (int64_t r = 0; r < R; ++r) {
      const T* gr = g + r * C;
      T* gxr = gx + r * C;
      if (nrm[r] > eps) {  // y = x/|x|: dx = (g - y (y.g)) / |x|
        const T* yr = y + r * C;
        T yg = 0;
        for (int64_t j = 0; j < C; ++j) yg += yr[j] * gr[j];
        for (int64_t j = 0; j < C; ++j) gxr[j] += (gr[j] - yr[j] * yg) / nrm[r];
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

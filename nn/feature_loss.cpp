#include "nn/feature_loss.hpp"

#include "autograd/ops_elementwise.hpp"
#include "autograd/ops_loss.hpp"

#include <algorithm>
#include <cmath>

namespace nn {

// Per pixel p (vectors a_p, b_p over channels, stride HW): na = max(|a|, eps), nb likewise,
// cos = a.b / (na nb). L = 1 - mean_p cos. dcos/da = b / (na nb) - cos a / na^2 where |a| > eps,
// b / (na nb) where the norm is clamped (constant), and symmetrically for b.
// Overflow-safe: each vector is scaled by its largest |entry| m first (a = m u, 1 <= |u| <=
// sqrt(C)), so |a| = m |u| and cos = (u.v) (m_a / na) (m_b / nb) never form a.a or a.b, which
// over- or underflow for float32 entries beyond ~1e19 or below ~1e-19 (float64: 1e154, 1e-154).
// The gradient is written with the bounded ratios r = m / n in [0, 1] and 1 / n.
template <class T> ag::Tensor<T> cosine_distance_channels(const ag::Tensor<T>& a, const ag::Tensor<T>& b, T eps) {
  ag::check_same_shape("cosine_distance_channels", a.shape(), b.shape());
  if (a.dim() != 4) throw ag::Error("cosine_distance_channels: needs [N x C x H x W], got " + ag::shape_str(a.shape()));
  if (!(eps > 0) || !std::isfinite(eps)) throw ag::Error("cosine_distance_channels: eps must be finite and > 0");
  const int64_t N = a.size(0), C = a.size(1), HW = a.size(2) * a.size(3), P = N * HW;
  if (P == 0 || C == 0) throw ag::Error("cosine_distance_channels: empty input " + ag::shape_str(a.shape()));
  // Per pixel: cos, the clamped norms na, nb and the ratios ra = ma / na, rb = mb / nb.
  std::vector<T> cosv(static_cast<size_t>(P)), na(static_cast<size_t>(P)), nb(static_cast<size_t>(P)),
      ra(static_cast<size_t>(P)), rb(static_cast<size_t>(P));
  const T* A = a.data();
  const T* B = b.data();
  double total = 0;
#pragma omp parallel for schedule(static) reduction(+ : total) if (P * C >= ag::kParallelMin)
  for (int64_t p = 0; p < P; ++p) {
    const int64_t n = p / HW, q = p % HW;
    const T* ap = A + n * C * HW + q;
    const T* bp = B + n * C * HW + q;
    T ma = 0, mb = 0;
    for (int64_t c = 0; c < C; ++c) ma = std::max(ma, std::abs(ap[c * HW])), mb = std::max(mb, std::abs(bp[c * HW]));
    // Divided, not multiplied by 1 / m: 1 / m overflows for subnormal m.
    const T da = ma > 0 ? ma : T(1), db = mb > 0 ? mb : T(1);
    T uv = 0, uu = 0, vv = 0;
    for (int64_t c = 0; c < C; ++c) {
      const T x = ap[c * HW] / da, y = bp[c * HW] / db;
      uv += x * y;
      uu += x * x;
      vv += y * y;
    }
    const T lu = std::sqrt(uu), lv = std::sqrt(vv);
    na[p] = std::max(ma * lu, eps);
    nb[p] = std::max(mb * lv, eps);
    ra[p] = na[p] > eps ? T(1) / lu : ma / eps;
    rb[p] = nb[p] > eps ? T(1) / lv : mb / eps;
    cosv[p] = uv * ra[p] * rb[p];
    total += static_cast<double>(cosv[p]);
  }
  ag::Tensor<T> out = ag::Tensor<T>::full({1, 1}, static_cast<T>(1.0 - total / static_cast<double>(P)));
  ag::record(out.node(), {a.node_ptr(), b.node_ptr()},
             [an = &a.node(), bn = &b.node(), on = &out.node(), cosv = std::move(cosv), na = std::move(na),
              nb = std::move(nb), ra = std::move(ra), rb = std::move(rb), C, HW, P, eps] {
               if (on->grad.empty()) return;
               const T g = -on->grad[0] / static_cast<T>(P);
               const bool ga = an->requires_grad, gb = bn->requires_grad;
               if (ga) an->ensure_grad();
               if (gb) bn->ensure_grad();
               const T* A = an->value.data();
               const T* B = bn->value.data();
#pragma omp parallel for schedule(static) if (P * C >= ag::kParallelMin)
               for (int64_t p = 0; p < P; ++p) {
                 const int64_t n = p / HW, q = p % HW, off = n * C * HW + q;
                 // b / (na nb) = (b / mb) rb / na and cos a / na^2 = cos (a / ma) ra / na, with
                 // u = a / ma (0 for a zero vector, whose ratio r is 0 too).
                 T ma = 0, mb = 0;
                 for (int64_t c = 0; c < C; ++c)
                   ma = std::max(ma, std::abs(A[off + c * HW])), mb = std::max(mb, std::abs(B[off + c * HW]));
                 const T da = ma > 0 ? ma : T(1), db = mb > 0 ? mb : T(1);
                 const T inv_a = T(1) / na[p], inv_b = T(1) / nb[p];
                 const T ca = na[p] > eps ? cosv[p] * ra[p] : T(0);
                 const T cb = nb[p] > eps ? cosv[p] * rb[p] : T(0);
                 for (int64_t c = 0; c < C; ++c) {
                   const int64_t i = off + c * HW;
                   const T u = A[i] / da, v = B[i] / db;
                   if (ga) an->grad[i] += g * inv_a * (v * rb[p] - ca * u);
                   if (gb) bn->grad[i] += g * inv_b * (u * ra[p] - cb * v);
                 }
               }
             });
  return out;
}

template <class T> ag::Tensor<T> feature_loss(const std::vector<ag::Tensor<T>>& pred,
                                              const std::vector<ag::Tensor<T>>& target, FeatureLossKind kind) {
  if (pred.size() != target.size() || pred.empty())
    throw ag::Error("feature_loss: " + std::to_string(pred.size()) + " predicted vs " + std::to_string(target.size()) +
                    " target layers");
  ag::Tensor<T> total;
  for (size_t l = 0; l < pred.size(); ++l) {
    ag::Tensor<T> term = kind == FeatureLossKind::Cosine ? cosine_distance_channels(pred[l], target[l])
                                                         : ag::l1_loss(pred[l], target[l]);
    total = total.defined() ? ag::add(total, term) : term;
  }
  return total;
}

template <class T> ag::Tensor<T> vgg_loss(const VGG19Features<T>& vgg, const ag::Tensor<T>& pred,
                                          const ag::Tensor<T>& target, FeatureLossKind kind) {
  std::vector<ag::Tensor<T>> ft;
  if (target.requires_grad()) {
    ft = vgg.features(target);
  } else {
    ag::NoGradGuard ng;
    ft = vgg.features(target);
  }
  return feature_loss(vgg.features(pred), ft, kind);
}

#define NN_FL_INST(T)                                                                                       \
  template ag::Tensor<T> cosine_distance_channels(const ag::Tensor<T>&, const ag::Tensor<T>&, T);           \
  template ag::Tensor<T> feature_loss(const std::vector<ag::Tensor<T>>&, const std::vector<ag::Tensor<T>>&, \
                                      FeatureLossKind);                                                     \
  template ag::Tensor<T> vgg_loss(const VGG19Features<T>&, const ag::Tensor<T>&, const ag::Tensor<T>&, FeatureLossKind);
NN_FL_INST(float)
NN_FL_INST(double)
#undef NN_FL_INST

}  // namespace nn

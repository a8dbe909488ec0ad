#include "autograd/ops_grouped.hpp"

#include <string>

namespace ag {
namespace {

// Rows bucketed by group (counting sort): rows of group g are perm[offset[g] .. offset[g+1]).
// When the group index is already non-decreasing, perm is the identity and the GEMMs run
// directly on the tensors' storage.
struct GroupPlan {
  std::vector<int64_t> offset, perm;
  bool sorted = true;
};

GroupPlan make_plan(const Index& group, int64_t G, const Shape& x_shape) {
  GroupPlan p;
  const int64_t N = static_cast<int64_t>(group.size());
  p.offset.assign(static_cast<size_t>(G + 1), 0);
  for (int64_t n = 0; n < N; ++n) {
    const int64_t g = group[n];
    if (g < 0 || g >= G)
      throw Error("grouped_linear: group " + std::to_string(g) + " of row " + std::to_string(n) +
                  " outside [0, " + std::to_string(G) + ") for x " + shape_str(x_shape));
    if (n > 0 && g < group[n - 1]) p.sorted = false;
    ++p.offset[g + 1];
  }
  for (int64_t g = 0; g < G; ++g) p.offset[g + 1] += p.offset[g];
  if (!p.sorted) {
    p.perm.resize(static_cast<size_t>(N));
    std::vector<int64_t> next(p.offset.begin(), p.offset.end() - 1);
    for (int64_t n = 0; n < N; ++n) p.perm[next[group[n]]++] = n;
  }
  return p;
}

// Rows of group g from `src` (row width w) as a contiguous matrix: a view when sorted,
// otherwise gathered into buf.
template <class T>
Eigen::Map<const RowMat<T>> group_rows(const GroupPlan& p, int64_t g, const T* src, int64_t w,
                                       RowMat<T>& buf) {
  const int64_t b = p.offset[g], n = p.offset[g + 1] - b;
  if (p.sorted) return Eigen::Map<const RowMat<T>>(src + b * w, n, w);
  buf.resize(n, w);
  for (int64_t k = 0; k < n; ++k) buf.row(k) = ConstMatMap<T>(src + p.perm[b + k] * w, 1, w);
  return Eigen::Map<const RowMat<T>>(buf.data(), n, w);
}

}  // namespace

template <class T>
Tensor<T> grouped_linear(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias,
                         const Index& group, int64_t out_features) {
  check_2d("grouped_linear", x.shape());
  check_2d("grouped_linear", weight.shape());
  const int64_t N = x.rows(), in = x.cols(), G = weight.rows(), out = out_features;
  if (out <= 0 || weight.cols() != out * in)
    throw Error("grouped_linear: weight " + shape_str(weight.shape()) + " does not hold " +
                std::to_string(out) + " x " + std::to_string(in) + " matrices for x " +
                shape_str(x.shape()));
  const bool has_bias = bias.defined();
  if (has_bias && bias.shape() != Shape{G, out})
    throw Error("grouped_linear: bias " + shape_str(bias.shape()) + " vs weight " +
                shape_str(weight.shape()) + " (need [G x out])");
  if (static_cast<int64_t>(group.size()) != N)
    throw Error("grouped_linear: " + std::to_string(group.size()) + " group indices for x " +
                shape_str(x.shape()));
  auto plan = std::make_shared<GroupPlan>(make_plan(group, G, x.shape()));

  auto y = new_output<T>({N, out});
  {
    const T* px = x.data();
    const T* pw = weight.data();
    const T* pb = has_bias ? bias.data() : nullptr;
    T* py = y.data();
    const GroupPlan& p = *plan;
#pragma omp parallel if (N * in * out > kParallelMin)
    {
      RowMat<T> xbuf, ybuf;
#pragma omp for schedule(dynamic, 8)
      for (int64_t g = 0; g < G; ++g) {
        const int64_t b = p.offset[g], n = p.offset[g + 1] - b;
        if (n == 0) continue;
        auto Xg = group_rows(p, g, px, in, xbuf);
        ConstMatMap<T> Wg(pw + g * out * in, out, in);
        if (p.sorted) {
          MatMap<T> Yg(py + b * out, n, out);
          Yg.noalias() = Xg * Wg.transpose();
          if (pb) Yg.rowwise() += ConstMatMap<T>(pb + g * out, 1, out).row(0);
        } else {
          ybuf.resize(n, out);
          ybuf.noalias() = Xg * Wg.transpose();
          if (pb) ybuf.rowwise() += ConstMatMap<T>(pb + g * out, 1, out).row(0);
          for (int64_t k = 0; k < n; ++k) MatMap<T>(py + p.perm[b + k] * out, 1, out) = ybuf.row(k);
        }
      }
    }
  }

  std::vector<std::shared_ptr<NodeBase>> parents{x.node_ptr(), weight.node_ptr()};
  if (has_bias) parents.push_back(bias.node_ptr());
  record(y.node(), std::move(parents),
         [xn = &x.node(), wn = &weight.node(), bn = has_bias ? &bias.node() : nullptr,
          yn = &y.node(), plan, N, in, out, G] {
           const GroupPlan& p = *plan;
           const bool gx = xn->requires_grad, gw = wn->requires_grad,
                      gb = bn && bn->requires_grad;
           if (gx) xn->ensure_grad();
           if (gw) wn->ensure_grad();
           if (gb) bn->ensure_grad();
           const T* px = xn->value.data();
           const T* pw = wn->value.data();
           const T* pgy = yn->grad.data();
#pragma omp parallel if (N * in * out > kParallelMin)
           {
             RowMat<T> xbuf, gbuf, dxbuf;
#pragma omp for schedule(dynamic, 8)
             for (int64_t g = 0; g < G; ++g) {
               const int64_t b = p.offset[g], n = p.offset[g + 1] - b;
               if (n == 0) continue;
               auto Gy = group_rows(p, g, pgy, out, gbuf);  // [n x out]
               if (gx) {  // dx = g W (conj W for complex: dL/dx = W^H g)
                 ConstMatMap<T> Wg(pw + g * out * in, out, in);
                 if (p.sorted) {
                   MatMap<T>(xn->grad.data() + b * in, n, in).noalias() += Gy * Wg.conjugate();
                 } else {
                   dxbuf.resize(n, in);
                   dxbuf.noalias() = Gy * Wg.conjugate();
                   for (int64_t k = 0; k < n; ++k)
                     MatMap<T>(xn->grad.data() + p.perm[b + k] * in, 1, in) += dxbuf.row(k);
                 }
               }
               if (gw) {  // dW = g^T conj(x)
                 auto Xg = group_rows(p, g, px, in, xbuf);
                 MatMap<T>(wn->grad.data() + g * out * in, out, in).noalias() +=
                     Gy.transpose() * Xg.conjugate();
               }
               if (gb) MatMap<T>(bn->grad.data() + g * out, 1, out) += Gy.colwise().sum();
             }
           }
         });
  return y;
}

#define AG_INSTANTIATE(T)                                                                 \
  template Tensor<T> grouped_linear<T>(const Tensor<T>&, const Tensor<T>&, const Tensor<T>&, \
                                       const Index&, int64_t);
AG_INSTANTIATE(float)
AG_INSTANTIATE(double)
AG_INSTANTIATE(std::complex<float>)
AG_INSTANTIATE(std::complex<double>)
#undef AG_INSTANTIATE

}  // namespace ag

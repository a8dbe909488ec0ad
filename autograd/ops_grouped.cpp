#include "autograd/ops_grouped.hpp"

#include "autograd/grouped_kernel.hpp"
#include "autograd/grouped_planes_kernel.hpp"

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
      throw Error("grouped_linear: group " + std::to_string(g) + " of row " + std::to_string(n) + " outside [0, " +
                  std::to_string(G) + ") for x " + shape_str(x_shape));
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
Eigen::Map<const RowMat<T>> group_rows(const GroupPlan& p, int64_t g, const T* src, int64_t w, RowMat<T>& buf) {
  const int64_t b = p.offset[g], n = p.offset[g + 1] - b;
  if (p.sorted) return Eigen::Map<const RowMat<T>>(src + b * w, n, w);
  buf.resize(n, w);
  for (int64_t k = 0; k < n; ++k) buf.row(k) = ConstMatMap<T>(src + p.perm[b + k] * w, 1, w);
  return Eigen::Map<const RowMat<T>>(buf.data(), n, w);
}

// ---- SIMD path (complex, rows sorted by group; see grouped_kernel.hpp) ----------------------
// weight(g) / bias(g) return group g's complex matrix / bias as views (bias: re == nullptr
// for none); each group is computed by one thread, so results do not depend on the count.
template <class R, class WF, class BF> void kernel_forward(const GroupPlan& p, int64_t G, const std::complex<R>* px,
                                                           std::complex<R>* py, int64_t in, int64_t out, WF weight,
                                                           BF bias) {
  const int64_t N = p.offset[G];
#pragma omp parallel if (N * in * out > kParallelMin)
  {
    grouped_kernel::Buffer<R> a, s;
    std::vector<std::complex<R>> bias_row;
#pragma omp for schedule(dynamic, 16)
    for (int64_t g = 0; g < G; ++g) {
      const int64_t b = p.offset[g], n = p.offset[g + 1] - b;
      if (n == 0) continue;
      std::complex<R>* yg = py + b * out;
      const grouped_kernel::CView<R> bv = bias(g);
      if (bv.re) {  // the bias row once, then copied to each row
        bias_row.resize(static_cast<size_t>(out));
        for (int64_t o = 0; o < out; ++o) bias_row[o] = {bv.re[o * bv.es], bv.im[o * bv.es]};
        for (int64_t k = 0; k < n; ++k) std::copy(bias_row.begin(), bias_row.end(), yg + k * out);
      }
      const grouped_kernel::CView<R> next = g + 1 < G ? weight(g + 1) : weight(g);
      const grouped_kernel::CView<R> w = weight(g);
      if (w.es == 1)  // planes: transposed into a and s, the outputs in the lanes
        grouped_planes_kernel::forward<R>(px + b * in, w, yg, n, in, out, a, s, g + 1 < G ? &next : nullptr);
      else
        grouped_kernel::forward<R>(px + b * in, w, yg, n, in, out, a, s, g + 1 < G ? &next : nullptr);
    }
  }
}

// dx (or null) += g W^H per group; dweight(g) / dbias(g): views to add dW, db into (re ==
// nullptr: not wanted), or to write them into when overwrite (every group's, zeros for a
// group without rows).
template <class R, class WF, class DWF, class DBF>
void kernel_backward(const GroupPlan& p, int64_t G, const std::complex<R>* px, const std::complex<R>* pgy,
                     std::complex<R>* dx, int64_t in, int64_t out, WF weight, DWF dweight, DBF dbias,
                     bool overwrite = false) {
  const int64_t N = p.offset[G];
#pragma omp parallel if (N * in * out > kParallelMin)
  {
    grouped_kernel::Buffer<R> a, s, xr, xi, nxi;
#pragma omp for schedule(dynamic, 16)
    for (int64_t g = 0; g < G; ++g) {
      const int64_t b = p.offset[g], n = p.offset[g + 1] - b;
      if (n == 0 && overwrite) {
        const grouped_kernel::View<R> dw = dweight(g), db = dbias(g);
        for (int64_t e = 0; dw.re && e < in * out; ++e) dw.re[e * dw.es] = dw.im[e * dw.es] = R(0);
        for (int64_t o = 0; db.re && o < out; ++o) db.re[o * db.es] = db.im[o * db.es] = R(0);
      }
      if (n == 0) continue;
      const std::complex<R>* gy = pgy + b * out;
      if (dx) {
        const grouped_kernel::CView<R> w = weight(g), next = g + 1 < G ? weight(g + 1) : w;
        if (w.es == 1)
          grouped_planes_kernel::backward_x<R>(gy, w, dx + b * in, n, in, out, g + 1 < G ? &next : nullptr);
        else
          grouped_kernel::backward_x<R>(gy, w, dx + b * in, n, in, out, a, s, g + 1 < G ? &next : nullptr);
      }
      const grouped_kernel::View<R> dw = dweight(g);
      if (dw.re && dw.es == 1) {
        const grouped_kernel::View<R> dw_next = g + 1 < G ? dweight(g + 1) : dw;
        grouped_planes_kernel::backward_w<R>(gy, px + b * in, dw, n, in, out, xr, xi, nxi,
                                             g + 1 < G ? &dw_next : nullptr, overwrite);
      } else if (dw.re)
        grouped_kernel::backward_w<R>(gy, px + b * in, dw, n, in, out, a, s);
      const grouped_kernel::View<R> db = dbias(g);
      for (int64_t o = 0; db.re && overwrite && o < out; ++o) db.re[o * db.es] = db.im[o * db.es] = R(0);
      if (db.re)
        for (int64_t k = 0; k < n; ++k)
          for (int64_t o = 0; o < out; ++o) {
            db.re[o * db.es] += gy[k * out + o].real();
            db.im[o * db.es] += gy[k * out + o].imag();
          }
    }
  }
}

}  // namespace

template <class T> Tensor<T> grouped_linear(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias,
                                            const Index& group, int64_t out_features) {
  check_2d("grouped_linear", x.shape());
  check_2d("grouped_linear", weight.shape());
  const int64_t N = x.rows(), in = x.cols(), G = weight.rows(), out = out_features;
  if (out <= 0 || weight.cols() != out * in)
    throw Error("grouped_linear: weight " + shape_str(weight.shape()) + " does not hold " + std::to_string(out) +
                " x " + std::to_string(in) + " matrices for x " + shape_str(x.shape()));
  const bool has_bias = bias.defined();
  if (has_bias && bias.shape() != Shape{G, out})
    throw Error("grouped_linear: bias " + shape_str(bias.shape()) + " vs weight " + shape_str(weight.shape()) +
                " (need [G x out])");
  if (static_cast<int64_t>(group.size()) != N)
    throw Error("grouped_linear: " + std::to_string(group.size()) + " group indices for x " + shape_str(x.shape()));
  auto plan = std::make_shared<GroupPlan>(make_plan(group, G, x.shape()));

  auto y = new_output<T>({N, out});
  {
    const T* px = x.data();
    const T* pw = weight.data();
    const T* pb = has_bias ? bias.data() : nullptr;
    T* py = y.data();
    const GroupPlan& p = *plan;
    if constexpr (is_complex_v<T>) {
      if (p.sorted) {  // SIMD kernel straight on the tensors
        using R = real_t<T>;
        kernel_forward<R>(
            p, G, px, py, in, out, [&](int64_t g) { return grouped_kernel::interleaved<R>(pw + g * out * in); },
            [&](int64_t g) {
              return pb ? grouped_kernel::interleaved<R>(pb + g * out) : grouped_kernel::CView<R>{nullptr, nullptr, 2};
            });
      }
    }
    const bool general = !is_complex_v<T> || !p.sorted;  // Eigen GEMM per group
#pragma omp parallel if (general && N * in * out > kParallelMin)
    if (general) {
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
  record(
      y.node(), std::move(parents),
      [xn = &x.node(), wn = &weight.node(), bn = has_bias ? &bias.node() : nullptr, yn = &y.node(), plan, N, in, out,
       G] {
        const GroupPlan& p = *plan;
        const bool gx = xn->requires_grad, gw = wn->requires_grad, gb = bn && bn->requires_grad;
        if (gx) xn->ensure_grad();
        if (gw) wn->ensure_grad();
        if (gb) bn->ensure_grad();
        const T* px = xn->value.data();
        const T* pw = wn->value.data();
        const T* pgy = yn->grad.data();
        if constexpr (is_complex_v<T>) {
          if (p.sorted) {  // SIMD kernels
            using R = real_t<T>;
            using V = grouped_kernel::View<R>;
            kernel_backward<R>(
                p, G, px, pgy, gx ? xn->grad.data() : nullptr, in, out,
                [&](int64_t g) { return grouped_kernel::interleaved<R>(pw + g * out * in); },
                [&](int64_t g) {
                  return gw ? grouped_kernel::interleaved<R>(wn->grad.data() + g * out * in) : V{nullptr, nullptr, 2};
                },
                [&](int64_t g) {
                  return gb ? grouped_kernel::interleaved<R>(bn->grad.data() + g * out) : V{nullptr, nullptr, 2};
                });
            return;
          }
        }
#pragma omp parallel if (N * in * out > kParallelMin)
        {
          RowMat<T> xbuf, gbuf, dxbuf;
#pragma omp for schedule(dynamic, 8)
          for (int64_t g = 0; g < G; ++g) {
            const int64_t b = p.offset[g], n = p.offset[g + 1] - b;
            if (n == 0) continue;
            auto Gy = group_rows(p, g, pgy, out, gbuf);  // [n x out]
            if (gx) {                                    // dx = g W (conj W for complex: dL/dx = W^H g)
              ConstMatMap<T> Wg(pw + g * out * in, out, in);
              if (p.sorted) {
                MatMap<T>(xn->grad.data() + b * in, n, in).noalias() += Gy * Wg.conjugate();
              } else {
                dxbuf.resize(n, in);
                dxbuf.noalias() = Gy * Wg.conjugate();
                for (int64_t k = 0; k < n; ++k) MatMap<T>(xn->grad.data() + p.perm[b + k] * in, 1, in) += dxbuf.row(k);
              }
            }
            if (gw) {  // dW = g^T conj(x)
              auto Xg = group_rows(p, g, px, in, xbuf);
              MatMap<T>(wn->grad.data() + g * out * in, out, in).noalias() += Gy.transpose() * Xg.conjugate();
            }
            if (gb) MatMap<T>(bn->grad.data() + g * out, 1, out) += Gy.colwise().sum();
          }
        }
      });
  return y;
}

template <class R> Tensor<std::complex<R>> grouped_linear_planes(const Tensor<std::complex<R>>& x, const Tensor<R>& re,
                                                                 const Tensor<R>& im, int64_t w_begin, int64_t b_begin,
                                                                 const Index& group, int64_t out_features) {
  using C = std::complex<R>;
  check_2d("grouped_linear_planes", x.shape());
  check_2d("grouped_linear_planes", re.shape());
  check_same_shape("grouped_linear_planes", re.shape(), im.shape());
  const int64_t N = x.rows(), in = x.cols(), G = re.rows(), P = re.cols(), out = out_features;
  if (out <= 0 || w_begin < 0 || w_begin + out * in > P || (b_begin >= 0 && b_begin + out > P))
    throw Error("grouped_linear_planes: columns [" + std::to_string(w_begin) + ", +" + std::to_string(out * in) +
                ") and bias at " + std::to_string(b_begin) + " do not fit planes " + shape_str(re.shape()) + " for x " +
                shape_str(x.shape()) + " and " + std::to_string(out) + " outputs");
  if (static_cast<int64_t>(group.size()) != N)
    throw Error("grouped_linear_planes: " + std::to_string(group.size()) + " group indices for x " +
                shape_str(x.shape()));
  auto plan = std::make_shared<GroupPlan>(make_plan(group, G, x.shape()));
  if (!plan->sorted) throw Error("grouped_linear_planes: group indices must be non-decreasing (rows sorted by group)");
  const bool has_bias = b_begin >= 0;
  auto y = new_output<C>({N, out});
  const R* pr = re.data();
  const R* pi = im.data();
  kernel_forward<R>(
      *plan, G, x.data(), y.data(), in, out,
      [&](int64_t g) {
        return grouped_kernel::CView<R>{pr + g * P + w_begin, pi + g * P + w_begin, 1};
      },
      [&](int64_t g) {
        return has_bias ? grouped_kernel::CView<R>{pr + g * P + b_begin, pi + g * P + b_begin, 1}
                        : grouped_kernel::CView<R>{nullptr, nullptr, 1};
      });
  record(y.node(), {x.node_ptr(), re.node_ptr(), im.node_ptr()},
         [xn = &x.node(), rn = &re.node(), imn = &im.node(), yn = &y.node(), plan, G, P, in, out, w_begin, b_begin,
          has_bias] {
           using V = grouped_kernel::View<R>;
           const bool gx = xn->requires_grad, gre = rn->requires_grad, gim = imn->requires_grad;
           if (gx) xn->ensure_grad();
           // The kernels write re and im together: both planes get a gradient buffer (the
           // one nobody asked for is written and ignored).
           const bool gw = gre || gim;
           // This layer's columns of both planes' gradients still unwritten (the first
           // backward into fresh planes, as in every training step): written, not added.
           ColumnRanges cols{{w_begin, w_begin + out * in}};
           if (has_bias) cols.push_back({b_begin, b_begin + out});
           const bool disjoint = !has_bias || b_begin + out <= w_begin || w_begin + out * in <= b_begin;
           const bool overwrite =
               gre && gim && disjoint && rn->grad_columns_unwritten(cols) && imn->grad_columns_unwritten(cols);
           if (overwrite) rn->claim_grad_columns(cols), imn->claim_grad_columns(cols);
           std::vector<R> unused_re, unused_im;
           R* dre = nullptr;
           R* dim = nullptr;
           if (overwrite) {
             dre = rn->grad.data(), dim = imn->grad.data();
           } else if (gw) {
             if (gre)
               rn->ensure_grad(), dre = rn->grad.data();
             else
               unused_re.assign(static_cast<size_t>(G * P), R(0)), dre = unused_re.data();
             if (gim)
               imn->ensure_grad(), dim = imn->grad.data();
             else
               unused_im.assign(static_cast<size_t>(G * P), R(0)), dim = unused_im.data();
           }
           const R* pr = rn->value.data();
           const R* pi = imn->value.data();
           kernel_backward<R>(
               *plan, G, xn->value.data(), yn->grad.data(), gx ? xn->grad.data() : nullptr, in, out,
               [&](int64_t g) {
                 return grouped_kernel::CView<R>{pr + g * P + w_begin, pi + g * P + w_begin, 1};
               },
               [&](int64_t g) {
                 return gw ? V{dre + g * P + w_begin, dim + g * P + w_begin, 1} : V{nullptr, nullptr, 1};
               },
               [&](int64_t g) {
                 return gw && has_bias ? V{dre + g * P + b_begin, dim + g * P + b_begin, 1} : V{nullptr, nullptr, 1};
               },
               overwrite);
         });
  return y;
}

template Tensor<std::complex<float>> grouped_linear_planes(const Tensor<std::complex<float>>&, const Tensor<float>&,
                                                           const Tensor<float>&, int64_t, int64_t, const Index&,
                                                           int64_t);
template Tensor<std::complex<double>> grouped_linear_planes(const Tensor<std::complex<double>>&, const Tensor<double>&,
                                                            const Tensor<double>&, int64_t, int64_t, const Index&,
                                                            int64_t);

#define AG_INSTANTIATE(T) \
  template Tensor<T> grouped_linear<T>(const Tensor<T>&, const Tensor<T>&, const Tensor<T>&, const Index&, int64_t);
AG_INSTANTIATE(float)
AG_INSTANTIATE(double)
AG_INSTANTIATE(std::complex<float>)
AG_INSTANTIATE(std::complex<double>)
#undef AG_INSTANTIATE

}  // namespace ag

#include "autograd/ops_conv.hpp"

#include "autograd/gemm_blocks.hpp"

#include <cstring>

namespace ag {

namespace {

void check_4d(const char* op, const Shape& s) {
  if (s.size() != 4) throw Error(std::string(op) + ": needs a 4-D tensor [N x C x H x W], got " + shape_str(s));
}

// im2col for a 3x3 kernel, stride 1, zero padding 1. img [C x H x W] -> col [(C*9) x (H*W)],
// row (c, ky, kx), column (y, x): col = img[c, y + ky - 1, x + kx - 1] or 0 outside.
template <class T> void im2col(const T* img, int64_t C, int64_t H, int64_t W, T* col) {
  const int64_t HW = H * W;
#pragma omp parallel for schedule(static) if (C * 9 * HW >= kParallelMin)
  for (int64_t r = 0; r < C * 9; ++r) {
    const int64_t c = r / 9, ky = (r % 9) / 3, kx = r % 3;
    const T* src = img + c * HW;
    T* dst = col + r * HW;
    for (int64_t y = 0; y < H; ++y) {
      const int64_t sy = y + ky - 1;
      T* d = dst + y * W;
      if (sy < 0 || sy >= H) {
        std::fill(d, d + W, T(0));
        continue;
      }
      const T* s = src + sy * W;
      // x + kx - 1 in [0, W): x in [1 - kx, W + 1 - kx)
      const int64_t x0 = std::max<int64_t>(0, 1 - kx), x1 = std::min<int64_t>(W, W + 1 - kx);
      for (int64_t x = 0; x < x0; ++x) d[x] = T(0);
      for (int64_t x = x0; x < x1; ++x) d[x] = s[x + kx - 1];
      for (int64_t x = x1; x < W; ++x) d[x] = T(0);
    }
  }
}

// The adjoint of im2col: img += scatter of col. Parallel over channels (the 9 rows of one
// channel write to the same image plane, so they stay in one thread).
template <class T> void col2im_add(const T* col, int64_t C, int64_t H, int64_t W, T* img) {
  const int64_t HW = H * W;
#pragma omp parallel for schedule(static) if (C * 9 * HW >= kParallelMin)
  for (int64_t c = 0; c < C; ++c) {
    T* dst = img + c * HW;
    for (int64_t k = 0; k < 9; ++k) {
      const int64_t ky = k / 3, kx = k % 3;
      const T* src = col + (c * 9 + k) * HW;
      const int64_t x0 = std::max<int64_t>(0, 1 - kx), x1 = std::min<int64_t>(W, W + 1 - kx);
      for (int64_t y = 0; y < H; ++y) {
        const int64_t sy = y + ky - 1;
        if (sy < 0 || sy >= H) continue;
        const T* s = src + y * W;
        T* d = dst + sy * W;
        for (int64_t x = x0; x < x1; ++x) d[x + kx - 1] += s[x];
      }
    }
  }
}

}  // namespace

// Per image n: Y_n [O x HW] = W [O x C9] * col(X_n) [C9 x HW] + b.
// Backward: dW += G_n col(X_n)^T, db += row sums of G_n, dX_n += col2im(W^T G_n).
// col(X_n) is recomputed in backward instead of stored (it is 9x the input).
template <class T> Tensor<T> conv2d_3x3(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias) {
  static_assert(!is_complex_v<T>, "conv2d_3x3: real scalars only");
  check_4d("conv2d_3x3", x.shape());
  check_4d("conv2d_3x3 (weight)", weight.shape());
  const int64_t N = x.size(0), C = x.size(1), H = x.size(2), W = x.size(3);
  const int64_t O = weight.size(0);
  if (weight.size(1) != C || weight.size(2) != 3 || weight.size(3) != 3)
    throw Error("conv2d_3x3: weight " + shape_str(weight.shape()) + " does not fit input " + shape_str(x.shape()) +
                " (weight must be [O x C x 3 x 3])");
  if (bias.defined() && bias.numel() != O)
    throw Error("conv2d_3x3: bias " + shape_str(bias.shape()) + " does not fit weight " + shape_str(weight.shape()));
  const int64_t HW = H * W, K = C * 9;
  Tensor<T> out = new_output<T>({N, O, H, W});
  {
    std::vector<T> col(static_cast<size_t>(K * HW));
    ConstMatMap<T> Wm(weight.data(), O, K);
    for (int64_t n = 0; n < N; ++n) {
      im2col(x.data() + n * C * HW, C, H, W, col.data());
      MatMap<T> Y(out.data() + n * O * HW, O, HW);
      const ConstMatMap<T> Col(col.data(), K, HW);
      gemm::tiles(O, HW, K, [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
        Y.block(r0, c0, r1 - r0, c1 - c0).noalias() = Wm.middleRows(r0, r1 - r0) * Col.middleCols(c0, c1 - c0);
      });
      if (bias.defined()) Y.colwise() += Eigen::Map<const Eigen::Matrix<T, Eigen::Dynamic, 1>>(bias.data(), O);
    }
  }
  std::vector<std::shared_ptr<NodeBase>> parents{x.node_ptr(), weight.node_ptr()};
  if (bias.defined()) parents.push_back(bias.node_ptr());
  record(out.node(), std::move(parents),
         [xn = &x.node(), wn = &weight.node(), bn = bias.defined() ? &bias.node() : nullptr, on = &out.node(), N, C, H,
          W, O, HW, K] {
           if (on->grad.empty()) return;
           const bool need_x = xn->requires_grad, need_w = wn->requires_grad;
           const bool need_b = bn && bn->requires_grad;
           if (need_x) xn->ensure_grad();
           if (need_w) wn->ensure_grad();
           if (need_b) bn->ensure_grad();
           ConstMatMap<T> Wm(wn->value.data(), O, K);
           std::vector<T> col(static_cast<size_t>(K * HW));
           for (int64_t n = 0; n < N; ++n) {
             ConstMatMap<T> G(on->grad.data() + n * O * HW, O, HW);
             if (need_w) {
               im2col(xn->value.data() + n * C * HW, C, H, W, col.data());
               MatMap<T> dW(wn->grad.data(), O, K);
               const ConstMatMap<T> Col(col.data(), K, HW);
               gemm::tiles(O, K, HW, [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
                 dW.block(r0, c0, r1 - r0, c1 - c0).noalias() +=
                     G.middleRows(r0, r1 - r0) * Col.middleRows(c0, c1 - c0).transpose();
               });
             }
             if (need_b) Eigen::Map<Eigen::Matrix<T, Eigen::Dynamic, 1>>(bn->grad.data(), O) += G.rowwise().sum();
             if (need_x) {
               MatMap<T> Col(col.data(), K, HW);
               gemm::tiles(K, HW, O, [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
                 Col.block(r0, c0, r1 - r0, c1 - c0).noalias() =
                     Wm.middleCols(r0, r1 - r0).transpose() * G.middleCols(c0, c1 - c0);
               });
               col2im_add(col.data(), C, H, W, xn->grad.data() + n * C * HW);
             }
           }
         });
  return out;
}

// out = mean of each 2x2 block; backward spreads g/4 to the four inputs.
template <class T> Tensor<T> avg_pool2x2(const Tensor<T>& x) {
  static_assert(!is_complex_v<T>, "avg_pool2x2: real scalars only");
  check_4d("avg_pool2x2", x.shape());
  const int64_t NC = x.size(0) * x.size(1), H = x.size(2), W = x.size(3);
  const int64_t Ho = H / 2, Wo = W / 2;
  if (Ho == 0 || Wo == 0) throw Error("avg_pool2x2: input " + shape_str(x.shape()) + " is smaller than 2x2");
  Tensor<T> out = new_output<T>({x.size(0), x.size(1), Ho, Wo});
  const T* X = x.data();
  T* Y = out.data();
#pragma omp parallel for schedule(static) if (NC * H * W >= kParallelMin)
  for (int64_t p = 0; p < NC; ++p)
    for (int64_t i = 0; i < Ho; ++i)
      for (int64_t j = 0; j < Wo; ++j) {
        const T* s = X + p * H * W + 2 * i * W + 2 * j;
        Y[(p * Ho + i) * Wo + j] = T(0.25) * (s[0] + s[1] + s[W] + s[W + 1]);
      }
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), NC, H, W, Ho, Wo] {
    if (on->grad.empty()) return;
    xn->ensure_grad();
    const T* G = on->grad.data();
    T* D = xn->grad.data();
#pragma omp parallel for schedule(static) if (NC * H * W >= kParallelMin)
    for (int64_t p = 0; p < NC; ++p)
      for (int64_t i = 0; i < Ho; ++i)
        for (int64_t j = 0; j < Wo; ++j) {
          const T g = T(0.25) * G[(p * Ho + i) * Wo + j];
          T* d = D + p * H * W + 2 * i * W + 2 * j;
          d[0] += g;
          d[1] += g;
          d[W] += g;
          d[W + 1] += g;
        }
  });
  return out;
}

// out = max of each 2x2 block (first maximum in row-major order wins a tie, NaN propagates);
// backward routes g to that element only.
template <class T> Tensor<T> max_pool2x2(const Tensor<T>& x) {
  static_assert(!is_complex_v<T>, "max_pool2x2: real scalars only");
  check_4d("max_pool2x2", x.shape());
  const int64_t NC = x.size(0) * x.size(1), H = x.size(2), W = x.size(3);
  const int64_t Ho = H / 2, Wo = W / 2;
  if (Ho == 0 || Wo == 0) throw Error("max_pool2x2: input " + shape_str(x.shape()) + " is smaller than 2x2");
  Tensor<T> out = new_output<T>({x.size(0), x.size(1), Ho, Wo});
  const bool track = grad_enabled() && x.requires_grad();
  std::vector<int64_t> arg(track ? static_cast<size_t>(NC * Ho * Wo) : 0);
  const T* X = x.data();
  T* Y = out.data();
#pragma omp parallel for schedule(static) if (NC * H * W >= kParallelMin)
  for (int64_t p = 0; p < NC; ++p)
    for (int64_t i = 0; i < Ho; ++i)
      for (int64_t j = 0; j < Wo; ++j) {
        const int64_t base = p * H * W + 2 * i * W + 2 * j;
        const int64_t cand[4] = {base, base + 1, base + W, base + W + 1};
        int64_t best = cand[0];
        for (int k = 1; k < 4; ++k) {
          const T v = X[cand[k]];
          if (v > X[best] || (v != v && X[best] == X[best])) best = cand[k];
        }
        const int64_t o = (p * Ho + i) * Wo + j;
        Y[o] = X[best];
        if (track) arg[o] = best;
      }
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), arg = std::move(arg)] {
    if (on->grad.empty()) return;
    xn->ensure_grad();
    const T* G = on->grad.data();
    T* D = xn->grad.data();
    // Windows do not overlap, so every input element receives from at most one output.
    const int64_t n = static_cast<int64_t>(arg.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
    for (int64_t o = 0; o < n; ++o) D[arg[o]] += G[o];
  });
  return out;
}

#define AG_CONV_INST(T)                                                                \
  template Tensor<T> conv2d_3x3(const Tensor<T>&, const Tensor<T>&, const Tensor<T>&); \
  template Tensor<T> avg_pool2x2(const Tensor<T>&);                                    \
  template Tensor<T> max_pool2x2(const Tensor<T>&);
AG_CONV_INST(float)
AG_CONV_INST(double)
#undef AG_CONV_INST

}  // namespace ag

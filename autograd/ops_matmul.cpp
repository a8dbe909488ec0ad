#include "autograd/ops_matmul.hpp"

#include "autograd/gemm_blocks.hpp"

#include <algorithm>
#include <string>

namespace ag {
using gemm::tiles;

// C = A B.  dA = G B^H,  dB = A^H G  (H = conjugate transpose; plain transpose for reals).
template <class T> Tensor<T> matmul(const Tensor<T>& a, const Tensor<T>& b) {
  check_2d("matmul", a.shape());
  check_2d("matmul", b.shape());
  if (a.cols() != b.rows())
    throw Error("matmul: inner sizes differ, " + shape_str(a.shape()) + " x " + shape_str(b.shape()));
  Tensor<T> out = new_output<T>({a.rows(), b.cols()});
  {
    MatMap<T> C = out.mat();
    const ConstMatMap<T> A = a.mat(), B = b.mat();
    tiles(A.rows(), B.cols(), A.cols(), [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
      C.block(r0, c0, r1 - r0, c1 - c0).noalias() += A.middleRows(r0, r1 - r0) * B.middleCols(c0, c1 - c0);
    });  // output zeroed already
  }
  record(out.node(), {a.node_ptr(), b.node_ptr()}, [an = &a.node(), bn = &b.node(), on = &out.node()] {
    const int64_t M = an->shape[0], K = an->shape[1], N = bn->shape[1];
    ConstMatMap<T> A(an->value.data(), M, K), B(bn->value.data(), K, N), G(on->grad.data(), M, N);
    if (an->requires_grad) {
      an->ensure_grad();
      MatMap<T> dA(an->grad.data(), M, K);
      tiles(M, K, N, [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
        dA.block(r0, c0, r1 - r0, c1 - c0).noalias() += G.middleRows(r0, r1 - r0) * B.middleRows(c0, c1 - c0).adjoint();
      });
    }
    if (bn->requires_grad) {
      bn->ensure_grad();
      MatMap<T> dB(bn->grad.data(), K, N);
      tiles(K, N, M, [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
        dB.block(r0, c0, r1 - r0, c1 - c0).noalias() += A.middleCols(r0, r1 - r0).adjoint() * G.middleCols(c0, c1 - c0);
      });
    }
  });
  return out;
}

namespace {
template <class T>
void check_linear(const char* op, const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias) {
  check_2d(op, x.shape());
  check_2d(op, weight.shape());
  if (x.cols() != weight.cols())
    throw Error(std::string(op) + ": input " + shape_str(x.shape()) + " does not fit weight " +
                shape_str(weight.shape()) + " (weight is out x in)");
  if (bias.defined() && bias.numel() != weight.rows())
    throw Error(std::string(op) + ": bias " + shape_str(bias.shape()) + " does not fit weight " +
                shape_str(weight.shape()));
}

// Gradients of Y = X W^T + b for the output gradient G: dX = G conj(W), dW = G^T conj(X),
// db = column sums of G.
template <class T> void linear_backward(Node<T>& xn, Node<T>& wn, Node<T>* bn, const T* g) {
  const int64_t N = xn.shape[0], I = xn.shape[1], O = wn.shape[0];
  ConstMatMap<T> X(xn.value.data(), N, I), W(wn.value.data(), O, I), G(g, N, O);
  // A first gradient is written tile by tile (each tile zeroed in cache by the product),
  // later ones added: no separate zero-filling pass over dX or dW.
  if (xn.requires_grad) {
    const bool first = xn.claim_whole_grad();
    MatMap<T> dX(xn.grad.data(), N, I);
    tiles(N, I, O, [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
      auto tile = dX.block(r0, c0, r1 - r0, c1 - c0);
      const auto prod = G.middleRows(r0, r1 - r0) * W.middleCols(c0, c1 - c0).conjugate();
      if (first)
        tile.noalias() = prod;
      else
        tile.noalias() += prod;
    });
  }
  if (wn.requires_grad) {
    const bool first = wn.claim_whole_grad();
    MatMap<T> dW(wn.grad.data(), O, I);
    tiles(O, I, N, [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
      auto tile = dW.block(r0, c0, r1 - r0, c1 - c0);
      const auto prod = G.middleCols(r0, r1 - r0).transpose() * X.middleCols(c0, c1 - c0).conjugate();
      if (first)
        tile.noalias() = prod;
      else
        tile.noalias() += prod;
    });
  }
  if (bn && bn->requires_grad) {
    bn->ensure_grad();
    // Plain loop in row order: an Eigen reduction's summation order can depend on the
    // data's alignment, i.e. on the heap, making runs differ in the last bits.
    T* gb = bn->grad.data();
    for (int64_t r = 0; r < N; ++r)
      for (int64_t o = 0; o < O; ++o) gb[o] += g[r * O + o];
  }
}
// Epilogues on columns [c0, c1) of one output row. Plain functions with restrict pointers:
// as loops inside the tile lambdas (captures by reference) they compiled to scalar code that
// reloaded the slope after every store (6.6% of a paper-preset inference frame).
template <class T> void add_row(T* __restrict y, const T* __restrict b, int64_t c0, int64_t c1) {
  for (int64_t c = c0; c < c1; ++c) y[c] += b[c];
}
template <class T>
void add_row_leaky_relu(T* __restrict y, const T* __restrict b, const T slope, int64_t c0, int64_t c1) {
  if (b)
    for (int64_t c = c0; c < c1; ++c) {
      const T v = y[c] + b[c];
      y[c] = v > 0 ? v : slope * v;
    }
  else
    for (int64_t c = c0; c < c1; ++c) y[c] = y[c] > 0 ? y[c] : slope * y[c];
}

// Y = X W^T in tiles (Y's elements need not be set before), then epilogue(r0, r1, c0, c1) on
// each tile while it is still in cache (bias, activation): one pass over Y instead of two.
template <class T, class Epilogue>
void gemm_xwt(const Tensor<T>& x, const Tensor<T>& weight, MatMap<T>& Y, Epilogue epilogue) {
  const ConstMatMap<T> X = x.mat(), W = weight.mat();
  tiles(X.rows(), W.rows(), X.cols(), [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
    Y.block(r0, c0, r1 - r0, c1 - c0).noalias() = X.middleRows(r0, r1 - r0) * W.middleRows(c0, c1 - c0).transpose();
    epilogue(r0, r1, c0, c1);
  });
}
}  // namespace

// Y = X W^T + b.  dX = G conj(W),  dW = G^T conj(X),  db = column sums of G.
template <class T> Tensor<T> linear(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias) {
  check_linear("linear", x, weight, bias);
  const int64_t out_f = weight.rows();
  Tensor<T> out = new_output_overwritten<T>({x.rows(), out_f});
  MatMap<T> Y = out.mat();
  const T* b = bias.defined() ? bias.data() : nullptr;
  T* y = Y.data();
  gemm_xwt(x, weight, Y, [y, b, out_f](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
    if (!b) return;
    for (int64_t r = r0; r < r1; ++r) add_row(y + r * out_f, b, c0, c1);
  });
  std::vector<std::shared_ptr<NodeBase>> parents{x.node_ptr(), weight.node_ptr()};
  if (bias.defined()) parents.push_back(bias.node_ptr());
  record(out.node(), std::move(parents),
         [xn = &x.node(), wn = &weight.node(), bn = bias.defined() ? &bias.node() : nullptr, on = &out.node()] {
           linear_backward<T>(*xn, *wn, bn, on->grad.data());
         });
  return out;
}

template <class T>
Tensor<T> linear_leaky_relu(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias, T slope) {
  static_assert(!is_complex_v<T>, "linear_leaky_relu: real scalars only");
  check_linear("linear_leaky_relu", x, weight, bias);
  if (!(slope > 0)) throw Error("linear_leaky_relu: slope must be > 0, got " + std::to_string(slope));
  const int64_t N = x.rows(), out_f = weight.rows();
  Tensor<T> out = new_output_overwritten<T>({N, out_f});
  MatMap<T> Y = out.mat();
  const T* b = bias.defined() ? bias.data() : nullptr;
  T* y = Y.data();
  gemm_xwt(x, weight, Y, [y, b, out_f, slope](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
    for (int64_t r = r0; r < r1; ++r) add_row_leaky_relu(y + r * out_f, b, slope, c0, c1);
  });
  std::vector<std::shared_ptr<NodeBase>> parents{x.node_ptr(), weight.node_ptr()};
  if (bias.defined()) parents.push_back(bias.node_ptr());
  record(out.node(), std::move(parents),
         [xn = &x.node(), wn = &weight.node(), bn = bias.defined() ? &bias.node() : nullptr, on = &out.node(), slope] {
           // Gradient before the activation: g * (y > 0 ? 1 : slope) (y > 0 iff x W^T + b > 0).
           const int64_t n = static_cast<int64_t>(on->value.size());
           std::vector<T> g(static_cast<size_t>(n));
           const T* y = on->value.data();
           const T* go = on->grad.data();
           T* gv = g.data();
           const T s = slope;
#pragma omp parallel for firstprivate(s) if (n > kParallelMin)
           for (int64_t i = 0; i < n; ++i) gv[i] = y[i] > 0 ? go[i] : s * go[i];
           linear_backward<T>(*xn, *wn, bn, g.data());
         });
  return out;
}

template <class T> Tensor<T> transpose(const Tensor<T>& a) {
  check_2d("transpose", a.shape());
  Tensor<T> out = new_output<T>({a.cols(), a.rows()});
  out.mat() = a.mat().transpose();
  record(out.node(), {a.node_ptr()}, [an = &a.node(), on = &out.node()] {
    an->ensure_grad();
    const int64_t M = an->shape[0], N = an->shape[1];
    MatMap<T>(an->grad.data(), M, N) += ConstMatMap<T>(on->grad.data(), N, M).transpose();
  });
  return out;
}

template Tensor<float> linear_leaky_relu(const Tensor<float>&, const Tensor<float>&, const Tensor<float>&, float);
template Tensor<double> linear_leaky_relu(const Tensor<double>&, const Tensor<double>&, const Tensor<double>&, double);

#define AG_INST(T)                                                                 \
  template Tensor<T> matmul(const Tensor<T>&, const Tensor<T>&);                   \
  template Tensor<T> linear(const Tensor<T>&, const Tensor<T>&, const Tensor<T>&); \
  template Tensor<T> transpose(const Tensor<T>&);
AG_INST(float)
AG_INST(double)
AG_INST(std::complex<float>)
AG_INST(std::complex<double>)

}  // namespace ag

#include "autograd/ops_matmul.hpp"

namespace ag {

// C = A B.  dA = G B^H,  dB = A^H G  (H = conjugate transpose; plain transpose for reals).
template <class T> Tensor<T> matmul(const Tensor<T>& a, const Tensor<T>& b) {
  check_2d("matmul", a.shape());
  check_2d("matmul", b.shape());
  if (a.cols() != b.rows())
    throw Error("matmul: inner sizes differ, " + shape_str(a.shape()) + " x " + shape_str(b.shape()));
  Tensor<T> out = new_output<T>({a.rows(), b.cols()});
  out.mat().noalias() = a.mat() * b.mat();
  record(out.node(), {a.node_ptr(), b.node_ptr()}, [an = &a.node(), bn = &b.node(), on = &out.node()] {
    const int64_t M = an->shape[0], K = an->shape[1], N = bn->shape[1];
    ConstMatMap<T> A(an->value.data(), M, K), B(bn->value.data(), K, N), G(on->grad.data(), M, N);
    if (an->requires_grad) {
      an->ensure_grad();
      MatMap<T>(an->grad.data(), M, K).noalias() += G * B.adjoint();
    }
    if (bn->requires_grad) {
      bn->ensure_grad();
      MatMap<T>(bn->grad.data(), K, N).noalias() += A.adjoint() * G;
    }
  });
  return out;
}

// Y = X W^T + b.  dX = G conj(W),  dW = G^T conj(X),  db = column sums of G.
template <class T>
Tensor<T> linear(const Tensor<T>& x, const Tensor<T>& weight, const Tensor<T>& bias) {
  check_2d("linear", x.shape());
  check_2d("linear", weight.shape());
  if (x.cols() != weight.cols())
    throw Error("linear: input " + shape_str(x.shape()) + " does not fit weight " + shape_str(weight.shape()) +
                " (weight is out x in)");
  const int64_t out_f = weight.rows();
  if (bias.defined() && bias.numel() != out_f)
    throw Error("linear: bias " + shape_str(bias.shape()) + " does not fit weight " + shape_str(weight.shape()));
  Tensor<T> out = new_output<T>({x.rows(), out_f});
  MatMap<T> Y = out.mat();
  Y.noalias() = x.mat() * weight.mat().transpose();
  if (bias.defined()) {
    Eigen::Map<const Eigen::Matrix<T, 1, Eigen::Dynamic>> bv(bias.data(), out_f);
    Y.rowwise() += bv;
  }
  std::vector<std::shared_ptr<NodeBase>> parents{x.node_ptr(), weight.node_ptr()};
  if (bias.defined()) parents.push_back(bias.node_ptr());
  record(out.node(), std::move(parents),
         [xn = &x.node(), wn = &weight.node(), bn = bias.defined() ? &bias.node() : nullptr, on = &out.node()] {
           const int64_t N = xn->shape[0], I = xn->shape[1], O = wn->shape[0];
           ConstMatMap<T> X(xn->value.data(), N, I), W(wn->value.data(), O, I), G(on->grad.data(), N, O);
           if (xn->requires_grad) {
             xn->ensure_grad();
             MatMap<T>(xn->grad.data(), N, I).noalias() += G * W.conjugate();
           }
           if (wn->requires_grad) {
             wn->ensure_grad();
             MatMap<T>(wn->grad.data(), O, I).noalias() += G.transpose() * X.conjugate();
           }
           if (bn && bn->requires_grad) {
             bn->ensure_grad();
             Eigen::Map<Eigen::Matrix<T, 1, Eigen::Dynamic>>(bn->grad.data(), O) += G.colwise().sum();
           }
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

#define AG_INST(T)                                                              \
  template Tensor<T> matmul(const Tensor<T>&, const Tensor<T>&);                \
  template Tensor<T> linear(const Tensor<T>&, const Tensor<T>&, const Tensor<T>&); \
  template Tensor<T> transpose(const Tensor<T>&);
AG_INST(float)
AG_INST(double)
AG_INST(std::complex<float>)
AG_INST(std::complex<double>)

}  // namespace ag

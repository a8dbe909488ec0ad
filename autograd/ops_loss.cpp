#include "autograd/ops_loss.hpp"

#include <cmath>
#include <string>

namespace ag {
namespace {

template <class T> void check_loss(const char* op, const Tensor<T>& p, const Tensor<T>& t) {
  check_same_shape(op, p.shape(), t.shape());
  if (p.numel() == 0) throw Error(std::string(op) + ": empty tensors " + shape_str(p.shape()));
}

// Shared backward: d/dp = g * dphi(p - t) / n, d/dt = -that.
template <class T, class D> void record_loss(Tensor<T>& out, const Tensor<T>& pred, const Tensor<T>& target, D dphi) {
  record(out.node(), {pred.node_ptr(), target.node_ptr()},
         [pn = &pred.node(), tn = &target.node(), on = &out.node(), dphi] {
           const int64_t n = static_cast<int64_t>(pn->value.size());
           const T s = on->grad[0] / T(n);
           const T* p = pn->value.data();
           const T* t = tn->value.data();
           if (pn->requires_grad) pn->ensure_grad();
           if (tn->requires_grad) tn->ensure_grad();
           T* gp = pn->requires_grad ? pn->grad.data() : nullptr;
           T* gt = tn->requires_grad ? tn->grad.data() : nullptr;
#pragma omp parallel for if (n > kParallelMin)
           for (int64_t i = 0; i < n; ++i) {
             const T d = s * dphi(p[i] - t[i]);
             if (gp) gp[i] += d;
             if (gt) gt[i] -= d;
           }
         });
}

}  // namespace

template <class T> Tensor<T> l1_loss(const Tensor<T>& pred, const Tensor<T>& target) {
  check_loss("l1_loss", pred, target);
  const int64_t n = pred.numel();
  const T* p = pred.data();
  const T* t = target.data();
  double acc = 0;  // accumulate in double: float sums over 1e6 elements lose digits
#pragma omp parallel for reduction(+ : acc) if (n > kParallelMin)
  for (int64_t i = 0; i < n; ++i) acc += std::abs(double(p[i]) - double(t[i]));
  auto out = Tensor<T>::scalar(T(acc / double(n)));
  record_loss(out, pred, target, [](T d) { return d > 0 ? T(1) : (d < 0 ? T(-1) : T(0)); });
  return out;
}

template <class T> Tensor<T> mse_loss(const Tensor<T>& pred, const Tensor<T>& target) {
  check_loss("mse_loss", pred, target);
  const int64_t n = pred.numel();
  const T* p = pred.data();
  const T* t = target.data();
  double acc = 0;
#pragma omp parallel for reduction(+ : acc) if (n > kParallelMin)
  for (int64_t i = 0; i < n; ++i) {
    const double d = double(p[i]) - double(t[i]);
    acc += d * d;
  }
  auto out = Tensor<T>::scalar(T(acc / double(n)));
  record_loss(out, pred, target, [](T d) { return T(2) * d; });
  return out;
}

template Tensor<float> l1_loss<float>(const Tensor<float>&, const Tensor<float>&);
template Tensor<double> l1_loss<double>(const Tensor<double>&, const Tensor<double>&);
template Tensor<float> mse_loss<float>(const Tensor<float>&, const Tensor<float>&);
template Tensor<double> mse_loss<double>(const Tensor<double>&, const Tensor<double>&);

}  // namespace ag

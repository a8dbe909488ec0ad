#include "autograd/ops_loss.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace ag {
namespace {

template <class T> void check_loss(const char* op, const Tensor<T>& p, const Tensor<T>& t) {
  check_same_shape(op, p.shape(), t.shape());
  if (p.numel() == 0) throw Error(std::string(op) + ": empty tensors " + shape_str(p.shape()));
}

// mean phi(p - t) as sum(phi(d)) / n; phi(d) = |d| or d^2 (power 1 or 2), homogeneous. Where
// that sum overflows (its terms near the largest float) while the mean need not, it is redone
// on p and t scaled by a power of two (exact) and scaled back after the division. The normal
// path is unchanged, bit for bit.
template <class T> double mean_of_power(const Tensor<T>& pred, const Tensor<T>& target, int power) {
  const int64_t n = pred.numel();
  const T* p = pred.data();
  const T* t = target.data();
  auto phi = [power](double d) { return power == 1 ? std::abs(d) : d * d; };
  double acc = 0;  // accumulate in double: float sums over 1e6 elements lose digits
#pragma omp parallel for reduction(+ : acc) if (n > kParallelMin)
  for (int64_t i = 0; i < n; ++i) acc += phi(double(p[i]) - double(t[i]));
  if (std::isfinite(acc) || std::isnan(acc)) return acc / double(n);
  double big = 0;
  for (int64_t i = 0; i < n; ++i) big = std::max({big, std::abs(double(p[i])), std::abs(double(t[i]))});
  if (!std::isfinite(big)) return acc / double(n);  // an input is inf itself
  const int k = std::ilogb(big) + 1;
  double scaled = 0;
  for (int64_t i = 0; i < n; ++i) scaled += phi(std::ldexp(double(p[i]), -k) - std::ldexp(double(t[i]), -k));
  return std::ldexp(scaled / double(n), power * k);
}

// Shared backward: d/dp = factor * g * dphi(p - t) / n, d/dt = -that (the factor applied
// before dphi, so 2 (p - t) is never formed: it overflows before the gradient does).
template <class T, class D>
void record_loss(Tensor<T>& out, const Tensor<T>& pred, const Tensor<T>& target, T factor, D dphi) {
  record(out.node(), {pred.node_ptr(), target.node_ptr()},
         [pn = &pred.node(), tn = &target.node(), on = &out.node(), factor, dphi] {
           const int64_t n = static_cast<int64_t>(pn->value.size());
           const T s = factor * on->grad[0] / T(n);
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
  auto out = Tensor<T>::scalar(T(mean_of_power(pred, target, 1)));
  record_loss(out, pred, target, T(1), [](T d) { return d > 0 ? T(1) : (d < 0 ? T(-1) : T(0)); });
  return out;
}

template <class T> Tensor<T> mse_loss(const Tensor<T>& pred, const Tensor<T>& target) {
  check_loss("mse_loss", pred, target);
  auto out = Tensor<T>::scalar(T(mean_of_power(pred, target, 2)));
  record_loss(out, pred, target, T(2), [](T d) { return d; });
  return out;
}

template Tensor<float> l1_loss<float>(const Tensor<float>&, const Tensor<float>&);
template Tensor<double> l1_loss<double>(const Tensor<double>&, const Tensor<double>&);
template Tensor<float> mse_loss<float>(const Tensor<float>&, const Tensor<float>&);
template Tensor<double> mse_loss<double>(const Tensor<double>&, const Tensor<double>&);

}  // namespace ag

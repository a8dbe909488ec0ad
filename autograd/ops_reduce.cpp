#include "autograd/ops_reduce.hpp"

namespace ag {
namespace {

// Sum of all elements times `scale` (scale = 1: sum, 1/n: mean).
template <class T> Tensor<T> scaled_total(const Tensor<T>& x, T scale) {
  Tensor<T> out = new_output<T>({1, 1});
  T s(0);
  for (const T& v : x.values()) s += v;
  out.data()[0] = s * scale;
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), scale] {
    xn->ensure_grad();
    const T g = on->grad[0] * scale;
    for (T& v : xn->grad) v += g;
  });
  return out;
}

// Per-row totals [R x 1] times scale.
template <class T> Tensor<T> scaled_rows(const Tensor<T>& x, T scale) {
  check_2d("sum_rows", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  Tensor<T> out = new_output<T>({R, 1});
  out.mat() = x.mat().rowwise().sum() * scale;
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), scale, R, C] {
    xn->ensure_grad();
    MatMap<T> gx(xn->grad.data(), R, C);
    ConstMatMap<T> g(on->grad.data(), R, 1);
    gx.colwise() += g.col(0) * scale;
  });
  return out;
}

// Per-column totals [1 x C] times scale.
template <class T> Tensor<T> scaled_cols(const Tensor<T>& x, T scale) {
  check_2d("sum_cols", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  Tensor<T> out = new_output<T>({1, C});
  out.mat() = x.mat().colwise().sum() * scale;
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), scale, R, C] {
    xn->ensure_grad();
    MatMap<T> gx(xn->grad.data(), R, C);
    ConstMatMap<T> g(on->grad.data(), 1, C);
    gx.rowwise() += g.row(0) * scale;
  });
  return out;
}

template <class T> T inverse_count(int64_t n, const char* op, const Shape& s) {
  if (n == 0) throw Error(std::string(op) + ": empty extent in " + shape_str(s));
  return T(1) / T(static_cast<real_t<T>>(n));
}

}  // namespace

template <class T> Tensor<T> sum(const Tensor<T>& x) { return scaled_total(x, T(1)); }
template <class T> Tensor<T> mean(const Tensor<T>& x) {
  return scaled_total(x, inverse_count<T>(x.numel(), "mean", x.shape()));
}
template <class T> Tensor<T> sum_rows(const Tensor<T>& x) { return scaled_rows(x, T(1)); }
template <class T> Tensor<T> mean_rows(const Tensor<T>& x) {
  check_2d("mean_rows", x.shape());
  return scaled_rows(x, inverse_count<T>(x.cols(), "mean_rows", x.shape()));
}
template <class T> Tensor<T> sum_cols(const Tensor<T>& x) { return scaled_cols(x, T(1)); }
template <class T> Tensor<T> mean_cols(const Tensor<T>& x) {
  check_2d("mean_cols", x.shape());
  return scaled_cols(x, inverse_count<T>(x.rows(), "mean_cols", x.shape()));
}

#define AG_INST(T)                                \
  template Tensor<T> sum(const Tensor<T>&);       \
  template Tensor<T> mean(const Tensor<T>&);      \
  template Tensor<T> sum_rows(const Tensor<T>&);  \
  template Tensor<T> mean_rows(const Tensor<T>&); \
  template Tensor<T> sum_cols(const Tensor<T>&);  \
  template Tensor<T> mean_cols(const Tensor<T>&);
AG_INST(float)
AG_INST(double)
AG_INST(std::complex<float>)
AG_INST(std::complex<double>)

}  // namespace ag

#include "autograd/ops_elementwise.hpp"

#include <algorithm>
#include <cmath>

namespace ag {
namespace {

template <class T> T cj(T x) {
  if constexpr (is_complex_v<T>)
    return std::conj(x);
  else
    return x;
}

// How an operand maps onto the [R x C] result of a broadcasting binary op.
struct Operand {
  int64_t rows = 1, cols = 1;  // operand's own extent (1 = broadcast along that dim)
  int64_t at(int64_t r, int64_t c) const { return (rows == 1 ? 0 : r) * cols + (cols == 1 ? 0 : c); }
};

struct Broadcast {
  Shape out_shape;
  int64_t R = 1, C = 1;
  Operand a, b;
  bool same = false;  // no broadcasting: flat elementwise loop
};

Broadcast broadcast(const char* op, const Shape& sa, const Shape& sb) {
  Broadcast bc;
  const int64_t na = numel_of(sa), nb = numel_of(sb);
  if (sa == sb) {
    bc.same = true;
    bc.out_shape = sa;
    bc.R = 1;
    bc.C = na;
    return bc;
  }
  auto fail = [&] {
    throw Error(std::string(op) + ": cannot broadcast shapes " + shape_str(sa) + " and " + shape_str(sb));
  };
  if (nb == 1 || na == 1) {
    const Shape& big = nb == 1 ? sa : sb;
    bc.out_shape = big;
    bc.R = 1;
    bc.C = numel_of(big);
    Operand full{1, bc.C}, one{1, 1};
    bc.a = nb == 1 ? full : one;
    bc.b = nb == 1 ? one : full;
    return bc;
  }
  if (sa.size() != 2 || sb.size() != 2) fail();
  for (int d = 0; d < 2; ++d)
    if (sa[d] != sb[d] && sa[d] != 1 && sb[d] != 1) fail();
  bc.R = std::max(sa[0], sb[0]);
  bc.C = std::max(sa[1], sb[1]);
  bc.out_shape = {bc.R, bc.C};
  bc.a = {sa[0], sa[1]};
  bc.b = {sb[0], sb[1]};
  return bc;
}

// f(a, b) -> value; da(a, b, out) and db(a, b, out) -> local partial derivatives. For complex
// (holomorphic) ops the incoming gradient is multiplied by the conjugate derivative.
// kAPasses / kBPasses: da / db is 1 everywhere (add, sub's a), so that operand's gradient is
// the output's, and it may take over the output's buffer (Node::take_grad) instead of a copy.
template <class T, bool kAPasses = false, bool kBPasses = false, class F, class DA, class DB>
Tensor<T> binary_op(const char* name, const Tensor<T>& a, const Tensor<T>& b, F f, DA da, DB db) {
  const Broadcast bc = broadcast(name, a.shape(), b.shape());
  Tensor<T> out = new_output_overwritten<T>(bc.out_shape);  // every element written below
  const T* av = a.data();
  const T* bv = b.data();
  T* ov = out.data();
  const int64_t n = bc.R * bc.C;
  if (bc.same) {
    // firstprivate: f's captures are then thread-local copies that no store can alias, so
    // the loop is vectorised (shared, they were reloaded after every store: scalar code).
#pragma omp parallel for firstprivate(f) if (n > kParallelMin)
    for (int64_t i = 0; i < n; ++i) ov[i] = f(av[i], bv[i]);
  } else {
    for (int64_t r = 0; r < bc.R; ++r)
      for (int64_t c = 0; c < bc.C; ++c) ov[r * bc.C + c] = f(av[bc.a.at(r, c)], bv[bc.b.at(r, c)]);
  }
  record(out.node(), {a.node_ptr(), b.node_ptr()}, [an = &a.node(), bn = &b.node(), on = &out.node(), bc, da, db] {
    const T* g = on->grad.data();
    const T* av = an->value.data();
    const T* bv = bn->value.data();
    const T* ov = on->value.data();
    const int64_t n = bc.R * bc.C;
    if (bc.same) {
      // a's part, then b's (a then b also when they are one tensor, as in mul(x, x)): each
      // writes a first gradient, or adds to one that is there.
      auto part = [&](Node<T>* pn, auto d) {
        if (!pn->requires_grad) return;
        const bool first = pn->claim_whole_grad();
        T* gp = pn->grad.data();
        if (first) {
#pragma omp parallel for firstprivate(d) if (n > kParallelMin)
          for (int64_t i = 0; i < n; ++i) gp[i] = g[i] * cj(d(av[i], bv[i], ov[i]));
        } else {
#pragma omp parallel for firstprivate(d) if (n > kParallelMin)
          for (int64_t i = 0; i < n; ++i) gp[i] += g[i] * cj(d(av[i], bv[i], ov[i]));
        }
      };
      // Distinct operands, one of which passes the gradient through: the other's part reads
      // the output's gradient first, then the buffer is handed over if it can be.
      if (an != bn && kAPasses && an->requires_grad && an->grad.empty()) {
        part(bn, db);
        if (!an->take_grad(*on)) part(an, da);
        return;
      }
      if (an != bn && kBPasses && bn->requires_grad && bn->grad.empty()) {
        part(an, da);
        if (!bn->take_grad(*on)) part(bn, db);
        return;
      }
      part(an, da);
      part(bn, db);
      return;
    }
    if (an->requires_grad) an->ensure_grad();
    if (bn->requires_grad) bn->ensure_grad();
    T* ga = an->requires_grad ? an->grad.data() : nullptr;
    T* gb = bn->requires_grad ? bn->grad.data() : nullptr;
    // Broadcast operands accumulate: serial.
    for (int64_t r = 0; r < bc.R; ++r)
      for (int64_t c = 0; c < bc.C; ++c) {
        const int64_t i = r * bc.C + c, ia = bc.a.at(r, c), ib = bc.b.at(r, c);
        if (ga) ga[ia] += g[i] * cj(da(av[ia], bv[ib], ov[i]));
        if (gb) gb[ib] += g[i] * cj(db(av[ia], bv[ib], ov[i]));
      }
  });
  return out;
}

// f(x) -> value; df(x, y) -> dy/dx.
template <class T, class F, class DF> Tensor<T> unary_op(const Tensor<T>& x, F f, DF df) {
  Tensor<T> out = new_output_overwritten<T>(x.shape());  // every element written below
  const T* xv = x.data();
  T* ov = out.data();
  const int64_t n = x.numel();
  // firstprivate: see binary_op (a branch-free, vectorised loop, e.g. for leaky_relu).
#pragma omp parallel for firstprivate(f) if (n > kParallelMin)
  for (int64_t i = 0; i < n; ++i) ov[i] = f(xv[i]);
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), df] {
    const bool first = xn->claim_whole_grad();  // write the first gradient, add later ones
    const int64_t n = static_cast<int64_t>(on->value.size());
    const T* g = on->grad.data();
    const T* xv = xn->value.data();
    const T* ov = on->value.data();
    T* gx = xn->grad.data();
    const DF d = df;
    if (first) {
#pragma omp parallel for firstprivate(d) if (n > kParallelMin)
      for (int64_t i = 0; i < n; ++i) gx[i] = g[i] * cj(d(xv[i], ov[i]));
    } else {
#pragma omp parallel for firstprivate(d) if (n > kParallelMin)
      for (int64_t i = 0; i < n; ++i) gx[i] += g[i] * cj(d(xv[i], ov[i]));
    }
  });
  return out;
}

}  // namespace

// ---- binary -------------------------------------------------------------------------------
template <class T> Tensor<T> add(const Tensor<T>& a, const Tensor<T>& b) {
  return binary_op<T, true, true>(
      "add", a, b, [](T x, T y) { return x + y; }, [](T, T, T) { return T(1); }, [](T, T, T) { return T(1); });
}
template <class T> Tensor<T> sub(const Tensor<T>& a, const Tensor<T>& b) {
  return binary_op<T, true>(
      "sub", a, b, [](T x, T y) { return x - y; }, [](T, T, T) { return T(1); }, [](T, T, T) { return T(-1); });
}
template <class T> Tensor<T> mul(const Tensor<T>& a, const Tensor<T>& b) {
  return binary_op<T>(
      "mul", a, b, [](T x, T y) { return x * y; }, [](T, T y, T) { return y; }, [](T x, T, T) { return x; });
}
template <class T> Tensor<T> div(const Tensor<T>& a, const Tensor<T>& b) {
  return binary_op<T>(
      "div", a, b, [](T x, T y) { return x / y; }, [](T, T y, T) { return T(1) / y; },
      [](T, T y, T o) { return -o / y; });
}
template <class T> Tensor<T> neg(const Tensor<T>& a) {
  return unary_op<T>(
      a, [](T x) { return -x; }, [](T, T) { return T(-1); });
}
template <class T> Tensor<T> add_scalar(const Tensor<T>& a, T s) {
  return unary_op<T>(
      a, [s](T x) { return x + s; }, [](T, T) { return T(1); });
}
template <class T> Tensor<T> mul_scalar(const Tensor<T>& a, T s) {
  return unary_op<T>(
      a, [s](T x) { return x * s; }, [s](T, T) { return s; });
}

// ---- unary (real) ----------------------------------------------------------------------------
template <class T> Tensor<T> exp(const Tensor<T>& x) {
  return unary_op<T>(
      x, [](T v) { return std::exp(v); }, [](T, T y) { return y; });
}
template <class T> Tensor<T> log(const Tensor<T>& x) {
  return unary_op<T>(
      x, [](T v) { return std::log(v); }, [](T v, T) { return T(1) / v; });
}
template <class T> Tensor<T> sqrt(const Tensor<T>& x) {
  return unary_op<T>(
      x, [](T v) { return std::sqrt(v); }, [](T, T y) { return T(0.5) / y; });
}
template <class T> Tensor<T> sin(const Tensor<T>& x) {
  return unary_op<T>(
      x, [](T v) { return std::sin(v); }, [](T v, T) { return std::cos(v); });
}
template <class T> Tensor<T> cos(const Tensor<T>& x) {
  return unary_op<T>(
      x, [](T v) { return std::cos(v); }, [](T v, T) { return -std::sin(v); });
}
template <class T> Tensor<T> tanh(const Tensor<T>& x) {
  return unary_op<T>(
      x, [](T v) { return std::tanh(v); }, [](T, T y) { return T(1) - y * y; });
}
template <class T> Tensor<T> abs(const Tensor<T>& x) {
  return unary_op<T>(
      x, [](T v) { return std::abs(v); }, [](T v, T) { return v > 0 ? T(1) : (v < 0 ? T(-1) : T(0)); });
}
template <class T> Tensor<T> square(const Tensor<T>& x) {
  return unary_op<T>(
      x, [](T v) { return v * v; }, [](T v, T) { return T(2) * v; });
}
template <class T> Tensor<T> pow(const Tensor<T>& x, T p) {
  return unary_op<T>(
      x, [p](T v) { return std::pow(v, p); }, [p](T v, T) { return p == T(0) ? T(0) : p * std::pow(v, p - T(1)); });
}
template <class T> Tensor<T> relu(const Tensor<T>& x) {
  return unary_op<T>(
      x, [](T v) { return v > 0 ? v : T(0); }, [](T v, T) { return v > 0 ? T(1) : T(0); });
}
template <class T> Tensor<T> leaky_relu(const Tensor<T>& x, T slope) {
  return unary_op<T>(
      x, [slope](T v) { return v > 0 ? v : slope * v; }, [slope](T v, T) { return v > 0 ? T(1) : slope; });
}
template <class T> Tensor<T> sigmoid(const Tensor<T>& x) {
  // Written so that neither branch overflows exp.
  return unary_op<T>(
      x,
      [](T v) {
        if (v >= 0) return T(1) / (T(1) + std::exp(-v));
        const T e = std::exp(v);
        return e / (T(1) + e);
      },
      [](T, T y) { return y * (T(1) - y); });
}
template <class T> Tensor<T> clamp(const Tensor<T>& x, T lo, T hi) {
  if (!(lo <= hi)) throw Error("clamp: lower bound above upper bound");
  return unary_op<T>(
      x, [lo, hi](T v) { return v < lo ? lo : (v > hi ? hi : v); },
      [lo, hi](T v, T) { return (v < lo || v > hi) ? T(0) : T(1); });
}

// atan2(y, x): d/dy = x / r^2, d/dx = -y / r^2, r^2 = x^2 + y^2; both 0 at the origin.
// Formed as (x / m) / (r / m)^2 / m with m = max(|x|, |y|), as hypot does, so that r^2 neither
// overflows nor underflows: exact wherever 1 / r is a finite float.
namespace {
template <class T> T atan2_partial(T num, T y, T x) {
  const T m = std::max(std::abs(x), std::abs(y));
  if (!(m > T(0))) return T(0);
  const T xs = x / m, ys = y / m;
  return num / m / (xs * xs + ys * ys) / m;
}
}  // namespace
template <class T> Tensor<T> atan2(const Tensor<T>& y, const Tensor<T>& x) {
  check_same_shape("atan2", y.shape(), x.shape());
  return binary_op<T>(
      "atan2", y, x, [](T a, T b) { return std::atan2(a, b); }, [](T a, T b, T) { return atan2_partial(b, a, b); },
      [](T a, T b, T) { return atan2_partial(-a, a, b); });
}

#define AG_ANY(T)                                             \
  template Tensor<T> add(const Tensor<T>&, const Tensor<T>&); \
  template Tensor<T> sub(const Tensor<T>&, const Tensor<T>&); \
  template Tensor<T> mul(const Tensor<T>&, const Tensor<T>&); \
  template Tensor<T> div(const Tensor<T>&, const Tensor<T>&); \
  template Tensor<T> neg(const Tensor<T>&);                   \
  template Tensor<T> add_scalar(const Tensor<T>&, T);         \
  template Tensor<T> mul_scalar(const Tensor<T>&, T);
#define AG_REAL(T)                                    \
  template Tensor<T> exp(const Tensor<T>&);           \
  template Tensor<T> log(const Tensor<T>&);           \
  template Tensor<T> sqrt(const Tensor<T>&);          \
  template Tensor<T> sin(const Tensor<T>&);           \
  template Tensor<T> cos(const Tensor<T>&);           \
  template Tensor<T> tanh(const Tensor<T>&);          \
  template Tensor<T> abs(const Tensor<T>&);           \
  template Tensor<T> square(const Tensor<T>&);        \
  template Tensor<T> pow(const Tensor<T>&, T);        \
  template Tensor<T> relu(const Tensor<T>&);          \
  template Tensor<T> leaky_relu(const Tensor<T>&, T); \
  template Tensor<T> sigmoid(const Tensor<T>&);       \
  template Tensor<T> clamp(const Tensor<T>&, T, T);   \
  template Tensor<T> atan2(const Tensor<T>&, const Tensor<T>&);

AG_ANY(float)
AG_ANY(double)
AG_ANY(std::complex<float>)
AG_ANY(std::complex<double>)
AG_REAL(float)
AG_REAL(double)

}  // namespace ag

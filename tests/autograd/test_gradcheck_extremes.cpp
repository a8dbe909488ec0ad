// Every op of the gradient-check suite (autograd/gradcheck_suite.cpp) at extreme input
// scales: mm (1e-3) and km (1e3), and near the ends of the float range ("tiny": entries or
// products near the smallest normal double, "huge": near the largest; "subnormal" where the op
// is meant to hold there). One row per op and scale. Each row asserts
//  - the float64 value is finite and matches a long-double reference written out here (never
//    the op itself), within 1e-12 relative (1e-5 for the float32 forward, run at the row's
//    float32 scale where it has one);
//  - the float64 gradient: central differences within the suite's 1e-6 (Grad::central), or,
//    where central differences cannot be formed (the op's period is below the spacing of the
//    doubles, the value is inf, the inputs are subnormal, or an offset hides them), the
//    analytic gradient against its closed form (Grad::closed), or, on the subnormal rows of
//    ops whose gradient is scale-free there, against the op's own at its "tiny" row
//    (Grad::like_tiny).
// Where the exact value or gradient lies beyond the largest float, the op must give inf of the
// right sign, as its header documents (rows marked inf_ok, with the reason).
// The coverage test fails if a suite op has no row here.
#include <doctest/doctest.h>

#include "autograd/gradcheck_suite.hpp"
#include "tests/support/ag_test_util.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <complex>
#include <limits>
#include <map>
#include <set>

namespace {

using namespace agt;
using LD = long double;
using CLD = std::complex<LD>;

struct LIn {  // an input as long doubles
  ag::Shape shape;
  std::vector<LD> v;
  int64_t cols() const { return shape.size() == 2 ? shape[1] : 1; }
  LD at(int64_t r, int64_t c) const { return v[static_cast<size_t>(r * cols() + c)]; }
};
using Ref = std::function<std::vector<LD>(const std::vector<LIn>&)>;
using DRef = std::function<std::vector<std::vector<LD>>(const std::vector<LIn>&)>;  // d sum(f) / d input
using F64 = std::function<Tensord(const std::vector<Tensord>&)>;
using F32 = std::function<Tensorf(const std::vector<Tensorf>&)>;
using Inputs = std::function<std::vector<Tensord>(double)>;

// like_tiny: the analytic gradient equals the op's own at its "tiny" row (itself checked),
// for ops whose gradient is constant to rounding below that scale (subnormal rows).
enum class Grad { central, closed, like_tiny };

struct Scale {
  std::string label;
  double s;        // the float64 scale
  double s32 = 0;  // the scale of the float32 forward check (0: none)
  Grad grad = Grad::central;
  bool inf_ok = false;  // the exact value or gradient exceeds the largest float somewhere
  Inputs inputs = {};   // overrides the op's inputs at this scale
  double step = 0;      // gradcheck's relative step if not its default (reason at the row)
};

struct OpRows {
  std::string op;
  F64 f;
  F32 f32;
  Inputs inputs;
  Ref ref;
  DRef dref;  // needed by Grad::closed rows
  std::vector<Scale> scales;
  ag::GradCheckOptions opt = {};
};

template <class V> using S = typename std::decay_t<V>::value_type::Scalar;

template <class G> OpRows op(std::string name, G g, Inputs in, Ref ref, std::vector<Scale> scales, DRef dref = {}) {
  OpRows r;
  r.op = std::move(name);
  r.f = [g](const std::vector<Tensord>& x) { return g(x); };
  r.f32 = [g](const std::vector<Tensorf>& x) { return g(x); };
  r.inputs = std::move(in);
  r.ref = std::move(ref);
  r.dref = std::move(dref);
  r.scales = std::move(scales);
  return r;
}

// Inputs base[i] * s^deg[i] (deg 2 for a bias added to a product of two scaled inputs).
Inputs scaled(std::vector<Tensord> base, std::vector<int> deg = {}) {
  return [base, deg](double s) {
    std::vector<Tensord> out;
    for (size_t i = 0; i < base.size(); ++i) {
      const int d = i < deg.size() ? deg[i] : 1;
      const double k = d == 0 ? 1.0 : (d == 1 ? s : s * s);
      std::vector<double> v = ag::to_vector(base[i].values());
      for (double& x : v) x *= k;
      out.push_back(Tensord::from(base[i].shape(), v));
    }
    return out;
  };
}

// mm and km, and the two ends of the range for an op whose value is homogeneous of the
// given degree in its inputs (1: linear, 2: a product of two inputs): the entries (or their
// products) reach 1e-300 and 1e300, and 1e-35 and 1e35 for the float32 forward.
std::vector<Scale> standard(int degree) {
  const double t = degree == 1 ? 1e-300 : 1e-150, h = degree == 1 ? 1e300 : 1e150;
  const double t32 = degree == 1 ? 1e-35 : 1e-17, h32 = degree == 1 ? 1e35 : 1e17;
  return {{"mm", 1e-3, 1e-3}, {"km", 1e3, 1e3}, {"tiny", t, t32}, {"huge", h, h32}};
}
std::vector<Scale> plus(std::vector<Scale> a, const std::vector<Scale>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// ---- reference helpers (long double) ----
std::vector<LD> map1(const LIn& a, const std::function<LD(LD)>& fn) {
  std::vector<LD> o;
  for (LD x : a.v) o.push_back(fn(x));
  return o;
}
// 2-D broadcast of b over a ([R x C] with [R x C], [1 x C] or [R x 1]).
std::vector<LD> bcast(const LIn& a, const LIn& b, const std::function<LD(LD, LD)>& fn) {
  std::vector<LD> o;
  for (int64_t r = 0; r < a.shape[0]; ++r)
    for (int64_t c = 0; c < a.shape[1]; ++c)
      o.push_back(fn(a.at(r, c), b.at(b.shape[0] == 1 ? 0 : r, b.shape[1] == 1 ? 0 : c)));
  return o;
}
std::vector<CLD> cplx_in(const LIn& re, const LIn& im) {
  std::vector<CLD> z;
  for (size_t i = 0; i < re.v.size(); ++i) z.emplace_back(re.v[i], im.v[i]);
  return z;
}
// [rows x cols] complex -> [re | im] columns, as the suite's split().
std::vector<LD> split_ref(const std::vector<CLD>& z, int64_t rows, int64_t cols) {
  std::vector<LD> o;
  for (int64_t r = 0; r < rows; ++r) {
    for (int64_t c = 0; c < cols; ++c) o.push_back(z[static_cast<size_t>(r * cols + c)].real());
    for (int64_t c = 0; c < cols; ++c) o.push_back(z[static_cast<size_t>(r * cols + c)].imag());
  }
  return o;
}
LD row_norm(const LIn& a, int64_t r) {
  LD s = 0;
  for (int64_t c = 0; c < a.cols(); ++c) s += a.at(r, c) * a.at(r, c);
  return std::sqrt(s);
}
// y[n][o] = sum_i W[o][i] x[n][i] (+ b[o]); W given as a function for the grouped layouts.
template <class X, class WF, class BF>
std::vector<X> affine(const std::vector<X>& x, int64_t n, int64_t in, int64_t out, WF w, BF b) {
  std::vector<X> y;
  for (int64_t r = 0; r < n; ++r)
    for (int64_t o = 0; o < out; ++o) {
      X s = b(r, o);
      for (int64_t i = 0; i < in; ++i) s += w(r, o, i) * x[static_cast<size_t>(r * in + i)];
      y.push_back(s);
    }
  return y;
}
std::vector<LD> normalise_ref(const LIn& a, bool per_row, LD eps) {
  const int64_t R = a.shape[0], C = a.shape[1];
  std::vector<LD> o(a.v.size());
  const int64_t groups = per_row ? R : C, len = per_row ? C : R;
  for (int64_t g = 0; g < groups; ++g) {
    auto idx = [&](int64_t k) { return static_cast<size_t>(per_row ? g * C + k : k * C + g); };
    LD m = 0, v = 0;
    for (int64_t k = 0; k < len; ++k) m += a.v[idx(k)];
    m /= len;
    for (int64_t k = 0; k < len; ++k) v += (a.v[idx(k)] - m) * (a.v[idx(k)] - m);
    v /= len;
    for (int64_t k = 0; k < len; ++k) o[idx(k)] = (a.v[idx(k)] - m) / std::sqrt(v + eps);
  }
  return o;
}

// ---- the table ----
const ag::Index kSelect = {3, 0, 0, 2}, kScatter = {1, 0, 1, 3}, kInterp = {0, 1, 2, 3, 2, 1};
const ag::Index kGroup5 = {1, 0, 1, 1, 0}, kGroup4 = {0, 1, 1, 0};

template <class R> ag::Tensor<R> split_t(const ag::Tensor<std::complex<R>>& z) {
  return ag::concat_cols<R>({ag::real(z), ag::imag(z)});
}

std::vector<OpRows> table() {
  std::vector<OpRows> t;
  const Tensord u43 = randn({4, 3}, 101), v43 = randn({4, 3}, 102), pos43 = randu({4, 3}, 103, 0.5, 2);
  const Tensord away43 = rand_signed({4, 3}, 104, 0.2, 1);  // away from kinks at 0
  const std::vector<Scale> lin = standard(1), bil = standard(2);

  t.push_back(op(
      "add (row broadcast)", [](const auto& x) { return ag::add(x[0], x[1]); }, scaled({u43, randn({1, 3}, 105)}),
      [](const std::vector<LIn>& a) { return bcast(a[0], a[1], [](LD p, LD q) { return p + q; }); }, lin));
  t.push_back(op(
      "sub (col broadcast)", [](const auto& x) { return ag::sub(x[0], x[1]); }, scaled({u43, randn({4, 1}, 106)}),
      [](const std::vector<LIn>& a) { return bcast(a[0], a[1], [](LD p, LD q) { return p - q; }); }, lin));
  t.push_back(op(
      "mul", [](const auto& x) { return ag::mul(x[0], x[1]); }, scaled({u43, v43}),
      [](const std::vector<LIn>& a) { return bcast(a[0], a[1], [](LD p, LD q) { return p * q; }); }, bil));
  // Both operands scaled alike: the quotient is O(1), its gradients 1/b and -a/b^2 are 1/s.
  t.push_back(op(
      "div", [](const auto& x) { return ag::div(x[0], x[1]); }, scaled({u43, pos43}),
      [](const std::vector<LIn>& a) { return bcast(a[0], a[1], [](LD p, LD q) { return p / q; }); }, lin));

  // exp of x*s: at km the exact value exceeds the largest double for x > 709.78 (float32:
  // 88.72) and exp (and its gradient, exp itself) is inf there, as ops_elementwise.hpp says;
  // central differences of inf are not formed, the gradient is checked in closed form.
  // "near overflow" / "near underflow": x just below log(DBL_MAX) and just above log(DBL_MIN).
  auto exp_d = [](const std::vector<LIn>& a) {
    return std::vector<std::vector<LD>>{map1(a[0], [](LD x) { return std::exp(x); })};
  };
  const auto band = [](unsigned seed) {
    return [seed](double top) { return std::vector<Tensord>{randu({4, 3}, seed, top - 8, top)}; };
  };
  t.push_back(op(
      "exp", [](const auto& x) { return ag::exp(x[0]); }, scaled({u43}),
      [exp_d](const std::vector<LIn>& a) { return exp_d(a)[0]; },
      {{"mm", 1e-3, 1e-3},
       {"km", 1e3, 1e3, Grad::closed, true},
       {"near overflow", 709.7, 88.7, Grad::central, false, band(107)},
       {"near underflow", -700, -79, Grad::central, false, band(108)}},
      exp_d));
  // log at subnormal x: the value is finite, the gradient 1/x exceeds the largest double
  // (x < 5.6e-309): inf, as the header says.
  t.push_back(op(
      "log", [](const auto& x) { return ag::log(x[0]); }, scaled({pos43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return std::log(x); }); },
      plus(lin, {{"subnormal", 1e-310, 1e-40, Grad::closed, true}}),
      [](const std::vector<LIn>& a) { return std::vector<std::vector<LD>>{map1(a[0], [](LD x) { return 1 / x; })}; }));
  t.push_back(op(
      "sqrt", [](const auto& x) { return ag::sqrt(x[0]); }, scaled({pos43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return std::sqrt(x); }); },
      plus(lin, {{"subnormal", 1e-310, 1e-40, Grad::closed}}),
      [](const std::vector<LIn>& a) {
        return std::vector<std::vector<LD>>{map1(a[0], [](LD x) { return 0.5L / std::sqrt(x); })};
      }));
  // sin, cos at 1e300: the period is far below the spacing of the doubles there, so central
  // differences mean nothing; the value (exact argument reduction) and the gradient in
  // closed form still must hold.
  t.push_back(op(
      "sin", [](const auto& x) { return ag::sin(x[0]); }, scaled({u43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return std::sin(x); }); },
      {{"mm", 1e-3, 1e-3}, {"km", 1e3, 1e3}, {"tiny", 1e-300, 1e-35}, {"huge", 1e300, 1e30, Grad::closed}},
      [](const std::vector<LIn>& a) {
        return std::vector<std::vector<LD>>{map1(a[0], [](LD x) { return std::cos(x); })};
      }));
  t.push_back(op(
      "cos", [](const auto& x) { return ag::cos(x[0]); }, scaled({u43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return std::cos(x); }); },
      // mm: cos x ~ 1 moves by h sin x ~ 1e-3 h, so the default step 1e-6 * 1e-3 leaves the
      // quotient to round-off (1e-16 / 2h = 5e-8 against gradients ~1e-4). cos varies on a
      // length of 1, not of the input's size: a step of 1e-5 (1e-2 of the scale) is still
      // small (truncation error h^2 / 6 ~ 2e-11 relative).
      {{"mm", 1e-3, 1e-3, Grad::central, false, {}, 1e-2},
       {"km", 1e3, 1e3},
       {"tiny", 1e-300, 1e-35},
       {"huge", 1e300, 1e30, Grad::closed}},
      [](const std::vector<LIn>& a) {
        return std::vector<std::vector<LD>>{map1(a[0], [](LD x) { return -std::sin(x); })};
      }));
  t.push_back(op(
      "tanh", [](const auto& x) { return ag::tanh(x[0]); }, scaled({u43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return std::tanh(x); }); }, lin));
  t.push_back(op(
      "abs", [](const auto& x) { return ag::abs(x[0]); }, scaled({away43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return std::fabs(x); }); }, lin));
  // x^2.5 reaches 1e-300 / 1e300 at x = 1e-120 / 1e120.
  t.push_back(op(
      "pow 2.5", [](const auto& x) { return ag::pow(x[0], S<decltype(x)>(2.5)); }, scaled({pos43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return std::pow(x, 2.5L); }); },
      {{"mm", 1e-3, 1e-3}, {"km", 1e3, 1e3}, {"tiny", 1e-120, 1e-14}, {"huge", 1e120, 1e14}}));
  t.push_back(op(
      "relu", [](const auto& x) { return ag::relu(x[0]); }, scaled({away43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return x > 0 ? x : 0; }); }, lin));
  t.push_back(op(
      "leaky_relu", [](const auto& x) { return ag::leaky_relu(x[0], S<decltype(x)>(0.02)); }, scaled({away43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return x > 0 ? x : LD(0.02) * x; }); }, lin));
  t.push_back(op(
      "sigmoid", [](const auto& x) { return ag::sigmoid(x[0]); }, scaled({u43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return 1 / (1 + std::exp(-x)); }); }, lin));
  t.push_back(op(
      "clamp", [](const auto& x) { return ag::clamp(x[0], S<decltype(x)>(-2), S<decltype(x)>(2)); }, scaled({u43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return std::min<LD>(std::max<LD>(x, -2), 2); }); },
      lin));
  t.push_back(op(
      "atan2", [](const auto& x) { return ag::atan2(x[0], x[1]); }, scaled({u43, v43}),
      [](const std::vector<LIn>& a) { return bcast(a[0], a[1], [](LD y, LD x) { return std::atan2(y, x); }); }, lin));

  t.push_back(op(
      "matmul", [](const auto& x) { return ag::matmul(x[0], x[1]); }, scaled({u43, randn({3, 5}, 109)}),
      [](const std::vector<LIn>& a) {
        return affine<LD>(
            a[0].v, 4, 3, 5, [&](int64_t, int64_t o, int64_t i) { return a[1].at(i, o); },
            [](int64_t, int64_t) { return LD(0); });
      },
      bil));
  t.push_back(op(
      "linear", [](const auto& x) { return ag::linear(x[0], x[1], x[2]); },
      scaled({u43, randn({5, 3}, 110), randn({1, 5}, 111)}, {1, 1, 2}),
      [](const std::vector<LIn>& a) {
        return affine<LD>(
            a[0].v, 4, 3, 5, [&](int64_t, int64_t o, int64_t i) { return a[1].at(o, i); },
            [&](int64_t, int64_t o) { return a[2].at(0, o); });
      },
      bil));
  t.push_back(op(
      "transpose", [](const auto& x) { return ag::transpose(x[0]); }, scaled({u43}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t c = 0; c < 3; ++c)
          for (int64_t r = 0; r < 4; ++r) o.push_back(a[0].at(r, c));
        return o;
      },
      lin));
  t.push_back(op(
      "sum_rows / mean_cols", [](const auto& x) { return ag::add(ag::sum_rows(x[0]), ag::mean(ag::mean_cols(x[0]))); },
      scaled({u43}),
      [](const std::vector<LIn>& a) {
        LD all = 0;
        for (LD x : a[0].v) all += x;
        std::vector<LD> o;
        for (int64_t r = 0; r < 4; ++r) o.push_back(a[0].at(r, 0) + a[0].at(r, 1) + a[0].at(r, 2) + all / 12);
        return o;
      },
      lin));
  t.push_back(op(
      "concat / slice",
      [](const auto& x) {
        return ag::slice_cols(ag::concat_cols<S<decltype(x)>>({x[0], x[1]}), 1, 4);
      },
      scaled({u43, randn({4, 2}, 112)}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t r = 0; r < 4; ++r)
          for (int64_t c = 1; c < 4; ++c) o.push_back(c < 3 ? a[0].at(r, c) : a[1].at(r, c - 3));
        return o;
      },
      lin));
  t.push_back(op(
      "index_select_rows", [](const auto& x) { return ag::index_select_rows(x[0], kSelect); }, scaled({u43}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t i : kSelect)
          for (int64_t c = 0; c < 3; ++c) o.push_back(a[0].at(i, c));
        return o;
      },
      lin));
  auto scatter_ref = [](const LIn& x, bool mean) {
    std::vector<LD> o(15, 0);
    std::vector<int> n(5, 0);
    for (size_t i = 0; i < kScatter.size(); ++i) {
      ++n[static_cast<size_t>(kScatter[i])];
      for (int64_t c = 0; c < 3; ++c) o[static_cast<size_t>(kScatter[i] * 3 + c)] += x.at(static_cast<int64_t>(i), c);
    }
    if (mean)
      for (size_t k = 0; k < o.size(); ++k) o[k] /= std::max(1, n[k / 3]);
    return o;
  };
  t.push_back(op(
      "scatter_add_rows", [](const auto& x) { return ag::scatter_add_rows(x[0], kScatter, 5); }, scaled({u43}),
      [scatter_ref](const std::vector<LIn>& a) { return scatter_ref(a[0], false); }, lin));
  t.push_back(op(
      "scatter_mean_rows", [](const auto& x) { return ag::scatter_mean_rows(x[0], kScatter, 5); }, scaled({u43}),
      [scatter_ref](const std::vector<LIn>& a) { return scatter_ref(a[0], true); }, lin));
  t.push_back(op(
      "add_gathered_rows", [](const auto& x) { return ag::add_gathered_rows(x[0], x[1], kSelect, x[2], kScatter); },
      scaled({u43, v43, randn({4, 3}, 121)}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t i = 0; i < 4; ++i)
          for (int64_t c = 0; c < 3; ++c)
            o.push_back(a[0].at(i, c) +
                        (a[1].at(kSelect[static_cast<size_t>(i)], c) + a[2].at(kScatter[static_cast<size_t>(i)], c)));
        return o;
      },
      lin));
  // Barycentric weights are unit-free: only the rows scale.
  t.push_back(op(
      "interpolate_rows", [](const auto& x) { return ag::interpolate_rows(x[0], kInterp, x[1]); },
      scaled({u43, randn({2, 3}, 113)}, {1, 0}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t i = 0; i < 2; ++i)
          for (int64_t c = 0; c < 3; ++c) {
            LD s = 0;
            for (int64_t k = 0; k < 3; ++k) s += a[1].at(i, k) * a[0].at(kInterp[static_cast<size_t>(i * 3 + k)], c);
            o.push_back(s);
          }
        return o;
      },
      lin));
  t.push_back(op(
      "dot_rows", [](const auto& x) { return ag::dot_rows(x[0], x[1]); }, scaled({u43, v43}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t r = 0; r < 4; ++r)
          o.push_back(a[0].at(r, 0) * a[1].at(r, 0) + a[0].at(r, 1) * a[1].at(r, 1) + a[0].at(r, 2) * a[1].at(r, 2));
        return o;
      },
      bil));
  t.push_back(op(
      "cross3", [](const auto& x) { return ag::cross3(x[0], x[1]); }, scaled({u43, v43}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t r = 0; r < 4; ++r)
          for (int64_t c = 0; c < 3; ++c) {
            const int64_t i = (c + 1) % 3, j = (c + 2) % 3;
            o.push_back(a[0].at(r, i) * a[1].at(r, j) - a[0].at(r, j) * a[1].at(r, i));
          }
        return o;
      },
      bil));
  // norm_rows up to 1e308 entries (|x| <= sqrt(3) 1e308 < DBL_MAX) and at subnormal lengths,
  // where the gradient x / |x| is a unit vector (closed form: central differences of
  // subnormals carry only ~13 digits).
  auto unit_rows = [](const std::vector<LIn>& a) {
    std::vector<LD> g;
    for (int64_t r = 0; r < a[0].shape[0]; ++r)
      for (int64_t c = 0; c < 3; ++c) g.push_back(a[0].at(r, c) / row_norm(a[0], r));
    return std::vector<std::vector<LD>>{g};
  };
  t.push_back(op(
      "norm_rows", [](const auto& x) { return ag::norm_rows(x[0]); }, scaled({away43}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t r = 0; r < 4; ++r) o.push_back(row_norm(a[0], r));
        return o;
      },
      plus(lin, {{"near overflow", 1e308, 1e38}, {"subnormal", 3e-310, 3e-40, Grad::closed}}), unit_rows));
  // eps = 1e-12 is in the units of x: rows shorter than it (tiny) give x / eps.
  t.push_back(op(
      "normalize_rows", [](const auto& x) { return ag::normalize_rows(x[0], S<decltype(x)>(1e-12)); }, scaled({away43}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t r = 0; r < 4; ++r)
          for (int64_t c = 0; c < 3; ++c) o.push_back(a[0].at(r, c) / std::max<LD>(row_norm(a[0], r), LD(1e-12)));
        return o;
      },
      plus(lin, {{"near overflow", 1e308, 1e38}})));
  // eps = 1e-5 is in the squared units of x: at mm it matters (var ~ 1e-6), at km not.
  t.push_back(op(
      "channel_norm", [](const auto& x) { return ag::channel_norm(x[0], S<decltype(x)>(1e-5)); },
      scaled({randn({6, 3}, 114)}), [](const std::vector<LIn>& a) { return normalise_ref(a[0], false, LD(1e-5)); },
      plus(lin, {{"near overflow", 1e307, 1e37}})));
  t.push_back(op(
      "layer_norm", [](const auto& x) { return ag::layer_norm(x[0], S<decltype(x)>(1e-5)); },
      scaled({randn({4, 5}, 115)}), [](const std::vector<LIn>& a) { return normalise_ref(a[0], true, LD(1e-5)); },
      plus(lin, {{"near overflow", 1e307, 1e37}})));
  t.push_back(op(
      "l1_loss", [](const auto& x) { return ag::l1_loss(x[0], x[1]); }, scaled({u43, v43}),
      [](const std::vector<LIn>& a) {
        LD s = 0;
        for (size_t i = 0; i < 12; ++i) s += std::fabs(a[0].v[i] - a[1].v[i]);
        return std::vector<LD>{s / 12};
      },
      // near overflow: the terms |p - t| (up to ~1e308) sum beyond the largest double, their
      // mean does not (was inf before the loss summed scaled where the plain sum overflows).
      plus(lin, {{"near overflow", 2e307, 2e37}})));
  t.push_back(op(
      "mse_loss", [](const auto& x) { return ag::mse_loss(x[0], x[1]); }, scaled({u43, v43}),
      [](const std::vector<LIn>& a) {
        LD s = 0;
        for (size_t i = 0; i < 12; ++i) s += (a[0].v[i] - a[1].v[i]) * (a[0].v[i] - a[1].v[i]);
        return std::vector<LD>{s / 12};
      },
      // near overflow: (p - t)^2 up to ~1e308, their sum beyond the largest double, the mean
      // not (was inf before).
      plus(bil, {{"near overflow", 5e153, 5e18}})));
  t.push_back(op(
      "grouped_linear", [](const auto& x) { return ag::grouped_linear(x[0], x[1], x[2], kGroup5, 2); },
      scaled({randn({5, 3}, 116), randn({2, 6}, 117), randn({2, 2}, 118)}, {1, 1, 2}),
      [](const std::vector<LIn>& a) {
        return affine<LD>(
            a[0].v, 5, 3, 2,
            [&](int64_t r, int64_t o, int64_t i) { return a[1].at(kGroup5[static_cast<size_t>(r)], o * 3 + i); },
            [&](int64_t r, int64_t o) { return a[2].at(kGroup5[static_cast<size_t>(r)], o); });
      },
      bil));
  t.push_back(op(
      "complex linear (complex_from, real, imag)",
      [](const auto& x) { return split_t(ag::linear(ag::complex_from(x[0], x[1]), ag::complex_from(x[2], x[3]), {})); },
      scaled({u43, v43, randn({2, 3}, 119), randn({2, 3}, 120)}),
      [](const std::vector<LIn>& a) {
        const std::vector<CLD> x = cplx_in(a[0], a[1]), w = cplx_in(a[2], a[3]);
        return split_ref(
            affine<CLD>(
                x, 4, 3, 2, [&](int64_t, int64_t o, int64_t i) { return w[static_cast<size_t>(o * 3 + i)]; },
                [](int64_t, int64_t) { return CLD(0); }),
            4, 2);
      },
      bil));
  // |z w| with |z w|^2 beyond the largest double at "huge" (1e153^2 = 1e306, squared 1e612).
  t.push_back(op(
      "complex mul / modulus",
      [](const auto& x) { return ag::modulus(ag::mul(ag::complex_from(x[0], x[1]), ag::complex_from(x[2], x[3]))); },
      scaled({away43, rand_signed({4, 3}, 121, 0.2, 1), rand_signed({4, 3}, 122, 0.2, 1),
              rand_signed({4, 3}, 123, 0.2, 1)}),
      [](const std::vector<LIn>& a) {
        const std::vector<CLD> z = cplx_in(a[0], a[1]), w = cplx_in(a[2], a[3]);
        std::vector<LD> o;
        for (size_t i = 0; i < z.size(); ++i) o.push_back(std::abs(z[i] * w[i]));
        return o;
      },
      {{"mm", 1e-3, 1e-3}, {"km", 1e3, 1e3}, {"tiny", 1e-153, 1e-18}, {"huge", 1e153, 1e18}}));
  t.push_back(op(
      "complex grouped_linear",
      [](const auto& x) {
        return split_t(ag::grouped_linear(ag::complex_from(x[0], x[1]), ag::complex_from(x[2], x[3]),
                                          ag::complex_from(x[4], x[5]), kGroup4, 2));
      },
      scaled({u43, v43, randn({2, 6}, 124), randn({2, 6}, 125), randn({2, 2}, 126), randn({2, 2}, 127)},
             {1, 1, 1, 1, 2, 2}),
      [](const std::vector<LIn>& a) {
        const std::vector<CLD> x = cplx_in(a[0], a[1]), w = cplx_in(a[2], a[3]), b = cplx_in(a[4], a[5]);
        auto g = [](int64_t r) { return kGroup4[static_cast<size_t>(r)]; };
        return split_ref(
            affine<CLD>(
                x, 4, 3, 2,
                [&](int64_t r, int64_t o, int64_t i) { return w[static_cast<size_t>(g(r) * 6 + o * 3 + i)]; },
                [&](int64_t r, int64_t o) { return b[static_cast<size_t>(g(r) * 2 + o)]; }),
            4, 2);
      },
      bil));
  // WIRE with omega0 = 5, s0 = 10: psi = exp(i 5 x - 100 |x|^2). At km and huge the envelope
  // is 0 (exp of -1e8 and of -inf) and so is the gradient; at tiny psi = 1.
  t.push_back(op(
      "wire",
      [](const auto& x) {
        using R = S<decltype(x)>;
        return split_t(ag::wire(ag::complex_from(x[0], x[1]), R(5), R(10)));
      },
      scaled({randu({4, 3}, 128, -0.15, 0.15), randu({4, 3}, 129, -0.15, 0.15)}),
      [](const std::vector<LIn>& a) {
        std::vector<CLD> z;
        for (const CLD& x : cplx_in(a[0], a[1])) z.push_back(std::exp(CLD(0, 5) * x - LD(100) * std::norm(x)));
        return split_ref(z, 4, 3);
      },
      // near overflow: psi = 0 and the factor 2 s0^2 a of the gradient is inf (|a| > 9e305):
      // the gradient was NaN (0 * inf) before wire skipped entries where psi underflowed.
      plus(lin, {{"near overflow", 1e308, 1e38}})));
  t.push_back(op(
      "square", [](const auto& x) { return ag::square(x[0]); }, scaled({u43}),
      [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return x * x; }); },
      {{"mm", 1e-3, 1e-3}, {"km", 1e3, 1e3}, {"tiny", 1e-150, 1e-17}, {"huge", 1e150, 1e17}}));
  // -2.5 x + 0.5: at tiny the offset 0.5 hides x (below its ulp), so L does not move under
  // central differences; the value 0.5 holds to rounding and the gradient in closed form.
  t.push_back(op(
      "neg / mul_scalar / add_scalar",
      [](const auto& x) {
        using T = S<decltype(x)>;
        return ag::add_scalar(ag::mul_scalar(ag::neg(x[0]), T(2.5)), T(0.5));
      },
      scaled({u43}), [](const std::vector<LIn>& a) { return map1(a[0], [](LD x) { return -2.5L * x + 0.5L; }); },
      {{"mm", 1e-3, 1e-3}, {"km", 1e3, 1e3}, {"tiny", 1e-300, 1e-35, Grad::closed}, {"huge", 1e300, 1e35}},
      [](const std::vector<LIn>& a) { return std::vector<std::vector<LD>>{map1(a[0], [](LD) { return -2.5L; })}; }));
  t.push_back(op(
      "sum / mean / mean_rows / sum_cols",
      [](const auto& x) {
        return ag::concat_cols<S<decltype(x)>>(
            {ag::add(ag::sum_cols(x[0]), ag::mean(x[0])), ag::transpose(ag::add(ag::mean_rows(x[0]), ag::sum(x[0])))});
      },
      scaled({u43}),
      [](const std::vector<LIn>& a) {
        LD all = 0;
        for (LD x : a[0].v) all += x;
        std::vector<LD> o;
        for (int64_t c = 0; c < 3; ++c)
          o.push_back(a[0].at(0, c) + a[0].at(1, c) + a[0].at(2, c) + a[0].at(3, c) + all / 12);
        for (int64_t r = 0; r < 4; ++r) o.push_back((a[0].at(r, 0) + a[0].at(r, 1) + a[0].at(r, 2)) / 3 + all);
        return o;
      },
      lin));
  t.push_back(op(
      "concat_rows / slice_rows / reshape",
      [](const auto& x) {
        return ag::reshape(ag::slice_rows(ag::concat_rows<S<decltype(x)>>({x[0], x[1]}), 1, 5), {3, 4});
      },
      scaled({u43, randn({2, 3}, 134)}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o(a[0].v.begin() + 3, a[0].v.end());  // rows 1..3 of the first, row 0 of the second
        o.insert(o.end(), a[1].v.begin(), a[1].v.begin() + 3);
        return o;
      },
      lin));
  t.push_back(op(
      "linear_leaky_relu", [](const auto& x) { return ag::linear_leaky_relu(x[0], x[1], x[2], S<decltype(x)>(0.02)); },
      scaled({u43, randn({5, 3}, 110), randn({1, 5}, 111)}, {1, 1, 2}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> y = affine<LD>(
            a[0].v, 4, 3, 5, [&](int64_t, int64_t o, int64_t i) { return a[1].at(o, i); },
            [&](int64_t, int64_t o) { return a[2].at(0, o); });
        for (LD& v : y) v = v > 0 ? v : LD(0.02) * v;
        return y;
      },
      bil));
  // Both operands scaled alike (as div): |w|^2 under- or overflows at tiny and huge unless
  // the quotient is formed scaled.
  t.push_back(op(
      "complex div",
      [](const auto& x) { return split_t(ag::div(ag::complex_from(x[0], x[1]), ag::complex_from(x[2], x[3]))); },
      scaled({u43, v43, pos43, randu({4, 3}, 135, 0.5, 2)}),
      [](const std::vector<LIn>& a) {
        const std::vector<CLD> z = cplx_in(a[0], a[1]), w = cplx_in(a[2], a[3]);
        std::vector<CLD> q;
        for (size_t i = 0; i < z.size(); ++i) q.push_back(z[i] / w[i]);
        return split_ref(q, 4, 3);
      },
      lin));
  // Planes [2 x 10]: column 0 and 9 unused, 1..6 the 2x3 weights, 7..8 the bias (scaled s^2,
  // as a bias added to x W).
  const Tensord pre = randn({2, 10}, 136), pim = randn({2, 10}, 137);
  auto planes = [u43, v43, pre, pim](double s) {
    std::vector<Tensord> in = scaled({u43, v43})(s);
    for (const Tensord& p : {pre, pim}) {
      std::vector<double> v = ag::to_vector(p.values());
      for (size_t k = 0; k < v.size(); ++k) v[k] *= (k % 10 == 7 || k % 10 == 8) ? s * s : s;
      in.push_back(Tensord::from(p.shape(), v));
    }
    return in;
  };
  t.push_back(op(
      "complex grouped_linear_planes",
      [](const auto& x) {
        return split_t(ag::grouped_linear_planes(ag::complex_from(x[0], x[1]), x[2], x[3], 1, 7, {0, 0, 1, 1}, 2));
      },
      planes,
      [](const std::vector<LIn>& a) {
        const std::vector<CLD> x = cplx_in(a[0], a[1]), p = cplx_in(a[2], a[3]);
        auto g = [](int64_t r) { return r < 2 ? 0 : 1; };
        return split_ref(
            affine<CLD>(
                x, 4, 3, 2,
                [&](int64_t r, int64_t o, int64_t i) { return p[static_cast<size_t>(g(r) * 10 + 1 + o * 3 + i)]; },
                [&](int64_t r, int64_t o) { return p[static_cast<size_t>(g(r) * 10 + 7 + o)]; }),
            4, 2);
      },
      bil));
  // The planes hold weights (~s) and biases (~s^2) side by side: each column is judged at its
  // own scale (one step of 1e-6 s^2 would make a weight entry s^2 and overflow at huge).
  t.back().opt.per_column = true;
  // Complex add / sub broadcast like the real ones, on both parts at once.
  auto cplx_bcast = [](const std::vector<LIn>& a, LD sign) {
    const std::vector<LD> re = bcast(a[0], a[2], [sign](LD p, LD q) { return p + sign * q; });
    const std::vector<LD> im = bcast(a[1], a[3], [sign](LD p, LD q) { return p + sign * q; });
    std::vector<CLD> z;
    for (size_t i = 0; i < re.size(); ++i) z.emplace_back(re[i], im[i]);
    return split_ref(z, 4, 3);
  };
  t.push_back(op(
      "complex add (row broadcast)",
      [](const auto& x) { return split_t(ag::add(ag::complex_from(x[0], x[1]), ag::complex_from(x[2], x[3]))); },
      scaled({u43, v43, randn({1, 3}, 138), randn({1, 3}, 139)}),
      [cplx_bcast](const std::vector<LIn>& a) { return cplx_bcast(a, 1); }, lin));
  t.push_back(op(
      "complex sub (col broadcast)",
      [](const auto& x) { return split_t(ag::sub(ag::complex_from(x[0], x[1]), ag::complex_from(x[2], x[3]))); },
      scaled({u43, v43, randn({4, 1}, 140), randn({4, 1}, 141)}),
      [cplx_bcast](const std::vector<LIn>& a) { return cplx_bcast(a, -1); }, lin));
  // x (real) times w = p + i q: x p + i x q, a product of two scaled inputs.
  t.push_back(op(
      "complex_from_real",
      [](const auto& x) { return split_t(ag::mul(ag::complex_from_real(x[0]), ag::complex_from(x[1], x[2]))); },
      scaled({u43, rand_signed({4, 3}, 142, 0.2, 1), rand_signed({4, 3}, 143, 0.2, 1)}),
      [](const std::vector<LIn>& a) {
        std::vector<CLD> z;
        for (size_t i = 0; i < a[0].v.size(); ++i) z.push_back(a[0].v[i] * CLD(a[1].v[i], a[2].v[i]));
        return split_ref(z, 4, 3);
      },
      bil));
  t.push_back(op(
      "conv2d_3x3", [](const auto& x) { return ag::conv2d_3x3(x[0], x[1], x[2]); },
      scaled({randn({1, 2, 5, 4}, 130), randn({3, 2, 3, 3}, 131), randn({1, 3}, 132)}, {1, 1, 2}),
      [](const std::vector<LIn>& a) {
        std::vector<LD> o;
        for (int64_t oc = 0; oc < 3; ++oc)
          for (int64_t h = 0; h < 5; ++h)
            for (int64_t w = 0; w < 4; ++w) {
              LD s = a[2].v[static_cast<size_t>(oc)];
              for (int64_t c = 0; c < 2; ++c)
                for (int64_t dy = 0; dy < 3; ++dy)
                  for (int64_t dx = 0; dx < 3; ++dx) {
                    const int64_t y = h + dy - 1, xx = w + dx - 1;
                    if (y < 0 || y >= 5 || xx < 0 || xx >= 4) continue;
                    s += a[1].v[static_cast<size_t>(((oc * 2 + c) * 3 + dy) * 3 + dx)] *
                         a[0].v[static_cast<size_t>((c * 5 + y) * 4 + xx)];
                  }
              o.push_back(s);
            }
        return o;
      },
      bil));
  auto pool_ref = [](const LIn& x, bool max) {
    std::vector<LD> o;
    for (int64_t c = 0; c < 2; ++c)
      for (int64_t h = 0; h < 2; ++h)
        for (int64_t w = 0; w < 3; ++w) {
          auto v = [&](int64_t dy, int64_t dx) {
            return x.v[static_cast<size_t>((c * 4 + 2 * h + dy) * 6 + 2 * w + dx)];
          };
          o.push_back(max ? std::max({v(0, 0), v(0, 1), v(1, 0), v(1, 1)})
                          : (v(0, 0) + v(0, 1) + v(1, 0) + v(1, 1)) / 4);
        }
    return o;
  };
  const Tensord img = randn({1, 2, 4, 6}, 133);
  t.push_back(op(
      "avg_pool2x2", [](const auto& x) { return ag::avg_pool2x2(x[0]); }, scaled({img}),
      [pool_ref](const std::vector<LIn>& a) { return pool_ref(a[0], false); }, lin));
  t.push_back(op(
      "max_pool2x2", [](const auto& x) { return ag::max_pool2x2(x[0]); }, scaled({img}),
      [pool_ref](const std::vector<LIn>& a) { return pool_ref(a[0], true); }, lin));

  // Subnormal inputs (1e-310, float32 1e-40) for the ops whose gradient no longer depends on
  // the scale below "tiny" (linear and piecewise-linear ops, and the smooth ones that are
  // linear near 0, the norms in their eps-dominated regime): the value against the reference
  // and the gradient against the op's own at "tiny". Central differences cannot be formed on
  // subnormals (they carry ~13 digits). Left out: products of two inputs (they underflow to
  // an exact 0), and ops whose gradient grows as 1 / x (log, div, atan2: inf there, as their
  // headers say) or vanishes with x (cos, pow).
  const std::set<std::string> kSubnormal = {"add (row broadcast)",
                                            "sub (col broadcast)",
                                            "sin",
                                            "tanh",
                                            "abs",
                                            "relu",
                                            "leaky_relu",
                                            "sigmoid",
                                            "clamp",
                                            "transpose",
                                            "sum_rows / mean_cols",
                                            "concat / slice",
                                            "index_select_rows",
                                            "scatter_add_rows",
                                            "add_gathered_rows",
                                            "scatter_mean_rows",
                                            "normalize_rows",
                                            "channel_norm",
                                            "layer_norm",
                                            "l1_loss",
                                            "wire",
                                            "neg / mul_scalar / add_scalar",
                                            "sum / mean / mean_rows / sum_cols",
                                            "concat_rows / slice_rows / reshape",
                                            "complex add (row broadcast)",
                                            "complex sub (col broadcast)",
                                            "avg_pool2x2",
                                            "max_pool2x2"};
  for (OpRows& o : t)
    if (kSubnormal.count(o.op)) o.scales.push_back({"subnormal", 1e-310, 1e-40, Grad::like_tiny});
  return t;
}

std::vector<LIn> as_ld(const std::vector<Tensord>& in) {
  std::vector<LIn> o;
  for (const Tensord& x : in) o.push_back({x.shape(), std::vector<LD>(x.values().begin(), x.values().end())});
  return o;
}

// v against the exact r: inf of r's sign where |r| exceeds the largest T (only if inf_ok),
// else finite and within tol relative to |r| (or to 1e-3 of the largest |r|, for entries
// that cancel), plus a few of T's smallest subnormals.
template <class T>
void check_against(const std::string& what, const T* v, const std::vector<LD>& ref, double tol, bool inf_ok) {
  LD big = 0;
  for (LD r : ref)
    if (std::fabs(r) <= std::numeric_limits<T>::max()) big = std::max(big, std::fabs(r));
  for (size_t i = 0; i < ref.size(); ++i) {
    const LD r = ref[i];
    const T x = v[i];
    INFO(what << " entry " << i << ": got " << double(x) << ", exact " << double(r));
    if (std::fabs(r) > std::numeric_limits<T>::max()) {
      CHECK(inf_ok);
      CHECK(std::isinf(x));
      CHECK(std::signbit(x) == std::signbit(r));
    } else {
      CHECK(std::isfinite(x));
      if (std::isfinite(x))
        CHECK(std::fabs(LD(x) - r) <=
              LD(tol) * std::max(std::fabs(r), LD(1e-3) * big) + 4 * std::numeric_limits<T>::denorm_min());
    }
  }
}

void run_row(const OpRows& o, const Scale& sc) {
  const std::string what = o.op + " at " + sc.label;
  CAPTURE(what);
  const Inputs& make = sc.inputs ? sc.inputs : o.inputs;
  std::vector<Tensord> in = make(sc.s);
  const std::vector<LIn> lin = as_ld(in);
  {
    ag::NoGradGuard ng;
    const Tensord y = o.f(in);
    const std::vector<LD> ref = o.ref(lin);
    REQUIRE(static_cast<size_t>(y.numel()) == ref.size());
    check_against(what + " (float64 value)", y.data(), ref, 1e-12, sc.inf_ok);
  }
  if (sc.s32 != 0) {
    std::vector<Tensorf> in32;
    for (const Tensord& x : make(sc.s32)) in32.push_back(to_float(x));
    std::vector<LIn> l32;
    for (const Tensorf& x : in32) l32.push_back({x.shape(), std::vector<LD>(x.values().begin(), x.values().end())});
    ag::NoGradGuard ng;
    const Tensorf y = o.f32(in32);
    check_against(what + " (float32 value)", y.data(), o.ref(l32), 1e-5, sc.inf_ok);
  }
  if (sc.grad == Grad::central) {
    ag::GradCheckOptions opt = o.opt;
    if (sc.step > 0) opt.step = sc.step;
    const ag::GradCheckResult r = ag::gradcheck(o.f, in, opt);
    CHECK(r.checked > 0);
    CHECK_MESSAGE(r.max_rel_error < 1e-6, what << ": " << r.report());
  } else if (sc.grad == Grad::like_tiny) {
    auto grads = [&](const Scale& at) {
      std::vector<Tensord> x = (at.inputs ? at.inputs : o.inputs)(at.s);
      for (Tensord& xi : x) xi.set_requires_grad(true);
      ag::sum(o.f(x)).backward();
      return x;
    };
    const auto tiny = std::find_if(o.scales.begin(), o.scales.end(), [](const Scale& x) { return x.label == "tiny"; });
    REQUIRE(tiny != o.scales.end());
    const std::vector<Tensord> here = grads(sc), ref = grads(*tiny);
    for (size_t k = 0; k < here.size(); ++k) {
      REQUIRE(here[k].has_grad());
      REQUIRE(ref[k].has_grad());
      const std::vector<LD> r(ref[k].grad().begin(), ref[k].grad().end());
      check_against(what + " (gradient of input " + std::to_string(k) + " against tiny)", here[k].grad().data(), r,
                    1e-12, false);
    }
  } else {
    REQUIRE(o.dref);
    for (Tensord& x : in) x.set_requires_grad(true);
    ag::sum(o.f(in)).backward();
    const std::vector<std::vector<LD>> d = o.dref(lin);
    REQUIRE(d.size() == in.size());
    for (size_t k = 0; k < in.size(); ++k) {
      REQUIRE(in[k].has_grad());
      check_against(what + " (gradient of input " + std::to_string(k) + ")", in[k].grad().data(), d[k], 1e-12,
                    sc.inf_ok);
    }
  }
}

}  // namespace

TEST_CASE("gradcheck extremes: every suite op has mm and km rows and a row at each end of the range") {
  const std::vector<OpRows> rows = table();
  std::map<std::string, std::set<std::string>> labels;
  for (const OpRows& o : rows)
    for (const Scale& s : o.scales) labels[o.op].insert(s.label);
  const std::vector<std::string> suite = ag::gradcheck_suite_ops();
  std::set<std::string> listed;
  for (const std::string& op : suite) {
    CAPTURE(op);
    listed.insert(op);
    REQUIRE_MESSAGE(labels.count(op), "no extreme-scale rows for suite op '" << op << "': add it to table()");
    CHECK(labels[op].count("mm"));
    CHECK(labels[op].count("km"));
    CHECK(labels[op].size() >= 4);  // and a small and a large end of the float range
  }
  for (const OpRows& o : rows) CHECK_MESSAGE(listed.count(o.op), "table row '" << o.op << "' is not a suite op");
  CHECK(rows.size() == suite.size());
  size_t n = 0;
  for (const OpRows& o : rows) n += o.scales.size();
  MESSAGE(n << " extreme-scale rows cover the " << rows.size() << " suite ops");
}

TEST_CASE("gradcheck extremes: values and gradients of every suite op at mm km tiny and huge scales") {
  for (const OpRows& o : table())
    for (const Scale& s : o.scales) run_row(o, s);
}

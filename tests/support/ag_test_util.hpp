// Shared helpers for the autograd tests: random inputs and a gradient-check assertion.
#pragma once

#include "autograd/autograd.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <string>

namespace agt {

using ag::Tensord;
using ag::Tensorf;
using Fn = std::function<Tensord(const std::vector<Tensord>&)>;

// Normal(offset, scale^2) entries, reproducible per seed.
inline Tensord randn(const ag::Shape& s, unsigned seed, double scale = 1.0, double offset = 0.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<double> v(static_cast<size_t>(ag::numel_of(s)));
  for (double& x : v) x = offset + scale * nd(rng);
  return Tensord::from(s, v);
}

// Uniform in [lo, hi).
inline Tensord randu(const ag::Shape& s, unsigned seed, double lo, double hi) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ud(lo, hi);
  std::vector<double> v(static_cast<size_t>(ag::numel_of(s)));
  for (double& x : v) x = ud(rng);
  return Tensord::from(s, v);
}

// Uniform magnitude in [lo, hi) with a random sign.
inline Tensord rand_signed(const ag::Shape& s, unsigned seed, double lo, double hi) {
  Tensord t = randu(s, seed, lo, hi);
  std::mt19937_64 rng(seed + 7777);
  for (double& x : t.values()) x = (rng() & 1) ? x : -x;
  return t;
}

inline ag::Index rand_index(int64_t n, int64_t bound, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int64_t> ui(0, bound - 1);
  ag::Index idx(static_cast<size_t>(n));
  for (auto& i : idx) i = ui(rng);
  return idx;
}

inline Tensorf to_float(const Tensord& t) {
  std::vector<float> v(t.values().begin(), t.values().end());
  return Tensorf::from(t.shape(), v);
}

inline double max_abs_diff(const Tensorf& a, const Tensord& b) {
  REQUIRE(a.shape() == b.shape());
  double m = 0;
  for (int64_t i = 0; i < a.numel(); ++i) m = std::max(m, std::abs(double(a.data()[i]) - b.data()[i]));
  return m;
}

inline double max_abs(const Tensord& t) {
  double m = 0;
  for (double v : t.values()) m = std::max(m, std::abs(v));
  return m;
}

inline bool all_finite(const ag::Storage<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// Gradient check of f at `inputs`: worst relative error below tol.
inline ag::GradCheckResult check_grad(const std::string& what, double tol, const Fn& f, std::vector<Tensord> inputs,
                                      const ag::GradCheckOptions& opt = {}) {
  ag::GradCheckResult r = ag::gradcheck(f, std::move(inputs), opt);
  INFO(what);
  CHECK(r.checked > 0);
  CHECK_MESSAGE(r.max_rel_error < tol, what << ": " << r.report());
  return r;
}

// For functions linear in every single input entry (linear, matmul, conv): central
// differences are exact up to round-off, so a large step removes the round-off that
// otherwise dominates when |L| is much larger than a gradient entry (inputs scaled 1e3).
inline ag::GradCheckOptions step_for_multilinear() {
  ag::GradCheckOptions o;
  o.step = 1e-2;
  return o;
}

// Complex tensor from two real leaves, and back to a real [R x 2C] tensor.
inline ag::Tensorcd cplx(const Tensord& re, const Tensord& im) { return ag::complex_from(re, im); }
inline Tensord split(const ag::Tensorcd& z) { return ag::concat_cols<double>({ag::real(z), ag::imag(z)}); }

// Every test built with this header runs with poisoned gradient claims: a gradient that an
// op claims to write (Node::claim_whole_grad, claim_grad_columns) starts as NaN, so an
// element it misses, or a column nobody writes that backward fails to zero, turns a check
// red instead of reading as memory that happened to be zero.
inline const bool kPoisonClaimedGrads = (ag::g_poison_claimed_grads = true);

}  // namespace agt

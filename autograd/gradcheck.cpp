#include "autograd/gradcheck.hpp"

#include "autograd/ops_elementwise.hpp"
#include "autograd/ops_reduce.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>

namespace ag {

std::string GradCheckResult::report() const {
  std::ostringstream o;
  o.precision(6);
  o << "gradcheck: worst relative error " << max_rel_error << " at input " << input << " element " << element
    << " (analytic " << analytic << ", numeric " << numeric << "), " << checked << " entries checked";
  return o.str();
}

GradCheckResult gradcheck(const std::function<Tensord(const std::vector<Tensord>&)>& f, std::vector<Tensord> inputs,
                          const GradCheckOptions& opt) {
  std::mt19937_64 rng(opt.seed);
  for (auto& x : inputs) {
    if (x.node().backward_fn || x.node().freed) throw Error("gradcheck: inputs must be leaves");
    x.zero_grad();
    x.set_requires_grad(true);
  }

  // Fixed random output weights: L = sum(w * f(inputs)).
  Tensord probe;
  {
    NoGradGuard ng;
    probe = f(inputs);
  }
  std::uniform_real_distribution<double> uw(0.5, 1.5);
  std::vector<double> w(static_cast<size_t>(probe.numel()));
  for (double& v : w) v = (rng() & 1 ? 1.0 : -1.0) * uw(rng);
  const Tensord weights = Tensord::from(probe.shape(), w);

  // L and |L| are summed in long double: outputs near the largest double (each finite) would
  // otherwise sum to inf, making the difference quotient NaN and the floor below inf (which
  // passes any gradient).
  using Wide = long double;
  auto loss_value = [&]() {
    NoGradGuard ng;
    const Tensord y = f(inputs);
    if (y.numel() != static_cast<int64_t>(w.size())) throw Error("gradcheck: output size changed between calls");
    Wide s = 0;
    for (size_t i = 0; i < w.size(); ++i) s += Wide(w[i]) * y.data()[i];
    return s;
  };
  Wide loss_magnitude = 0;  // sum |w f|: the size round-off in L is relative to
  for (size_t i = 0; i < w.size(); ++i) loss_magnitude += std::abs(Wide(w[i]) * probe.data()[i]);

  // Analytic gradients.
  {
    const Tensord y = f(inputs);
    if (!y.requires_grad()) throw Error("gradcheck: the output does not depend on any input");
    sum(mul(y, weights)).backward();
  }

  GradCheckResult res;
  for (size_t k = 0; k < inputs.size(); ++k) {
    Tensord& x = inputs[k];
    const int64_t n = x.numel();
    std::vector<int64_t> entries(static_cast<size_t>(n));
    std::iota(entries.begin(), entries.end(), 0);
    if (n > opt.max_entries_per_input) {
      std::shuffle(entries.begin(), entries.end(), rng);
      entries.resize(static_cast<size_t>(opt.max_entries_per_input));
    }
    const std::vector<double> analytic =
        x.has_grad() ? std::vector<double>(x.grad().begin(), x.grad().end()) : std::vector<double>(size_t(n), 0.0);

    // Groups judged together: the whole input, or each column of a 2-D input.
    const int64_t cols = opt.per_column && x.dim() == 2 ? x.cols() : 1;
    for (int64_t c = 0; c < cols; ++c) {
      std::vector<int64_t> group;
      for (int64_t i : entries)
        if (i % cols == c) group.push_back(i);
      if (group.empty()) continue;
      double scale = 0;  // the group's size: steps and the floor are relative to it
      for (int64_t i = c; i < n; i += cols) scale = std::max(scale, std::abs(x.values()[static_cast<size_t>(i)]));
      if (!(scale > 0) || !std::isfinite(scale)) scale = 1;

      std::vector<double> numeric(group.size());
      for (size_t e = 0; e < group.size(); ++e) {
        double& v = x.values()[static_cast<size_t>(group[e])];
        const double orig = v;
        const double h = opt.step * scale;
        const double xp = orig + h, xm = orig - h;
        v = xp;
        const Wide lp = loss_value();
        v = xm;
        const Wide lm = loss_value();
        v = orig;
        numeric[e] = static_cast<double>((lp - lm) / (Wide(xp) - Wide(xm)));
      }
      double largest = 0;
      for (double v : numeric) largest = std::max(largest, std::abs(v));
      const double floor =
          std::max({opt.floor_fraction * largest, opt.abs_floor, static_cast<double>(1e-12L * loss_magnitude / scale),
                    std::numeric_limits<double>::min()});
      for (size_t e = 0; e < group.size(); ++e) {
        const double a = analytic[static_cast<size_t>(group[e])], nu = numeric[e];
        double rel = std::abs(a - nu) / std::max({std::abs(a), std::abs(nu), floor});
        if (std::isnan(rel)) rel = INFINITY;  // a NaN gradient is the worst error
        if (res.input < 0 || rel > res.max_rel_error) {
          res.max_rel_error = rel;
          res.input = static_cast<int>(k);
          res.element = group[e];
          res.analytic = a;
          res.numeric = nu;
        }
        ++res.checked;
      }
    }
  }
  return res;
}

}  // namespace ag

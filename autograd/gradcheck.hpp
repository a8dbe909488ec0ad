// Gradient checking by central differences in float64.
#pragma once

#include "autograd/tensor.hpp"

#include <functional>
#include <string>

namespace ag {

struct GradCheckResult {
  double max_rel_error = 0;          // worst relative error over all checked entries
  int input = -1;                    // which input holds the worst entry
  int64_t element = -1;              // flat index of the worst entry in that input
  double analytic = 0, numeric = 0;  // the two values there
  int64_t checked = 0;               // number of entries compared
  std::string report() const;
};

struct GradCheckOptions {
  // Relative step: h = step * scale with scale = the largest |x| over that input (1 if it is
  // all zero), so the check behaves the same on inputs of size 1e-20 and 1e20. (A step
  // relative to each entry instead raises round-off on small entries; inputs whose columns
  // differ much in size are best checked one at a time, each with its own step.)
  // The difference quotient divides by the step actually taken, (x + h) - (x - h) in floating
  // point, not by the nominal 2h.
  double step = 1e-6;
  // Entries are compared as |a - n| / max(|a|, |n|, floor), floor = max(floor_fraction *
  // (largest |n| over the input), abs_floor, 1e-12 * |L| / scale) with |L| = sum |w f|: entries
  // far below the largest gradient of their input are judged against it, so round-off on tiny
  // gradients does not dominate; the last term is relative to the loss and input scale (a
  // fixed absolute floor would pass any gradient of inputs of size 1e-20).
  double floor_fraction = 1e-3;
  // A lower bound for that floor. Central differences of a loss L carry round-off of about
  // 1e-16 |L| / step; where L sums many outputs, gradients near that level are noise, and
  // abs_floor says below which size entries are judged by their absolute error instead.
  double abs_floor = 0;
  int64_t max_entries_per_input = 400;  // larger inputs: a deterministic random subset
  // 2-D inputs: each column is judged as an input of its own (its own scale for the step and
  // the floors), for tensors whose columns hold quantities of different sizes or units (e.g.
  // a first-layer weight on unit-free and metric features).
  bool per_column = false;
  unsigned seed = 1;
};

// f maps the inputs to a tensor; the check differentiates L = sum(w * f(inputs)) with fixed
// random weights w. Analytic gradients come from backward(); numeric ones from central
// differences of L (L summed in long double, so outputs near the largest double do not
// overflow it). Inputs must be leaves; they are restored afterwards.
GradCheckResult gradcheck(const std::function<Tensord(const std::vector<Tensord>&)>& f, std::vector<Tensord> inputs,
                          const GradCheckOptions& opt = {});

}  // namespace ag

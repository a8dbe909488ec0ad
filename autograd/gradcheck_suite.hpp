// A summary gradient check over every op of the library on random float64 inputs: what
// `gdsr demo` prints. (The per-op tests in tests/autograd/ go further:
// extremes, broadcasting variants, errors.)
#pragma once

#include "autograd/gradcheck.hpp"

#include <functional>
#include <string>
#include <vector>

namespace ag {

struct NamedGradCheck {
  std::string op;
  GradCheckResult result;
  double tolerance = 1e-6;
  bool passed() const { return result.max_rel_error < tolerance; }
};

// Runs all checks; `progress(done, total)` after each one (may be empty).
std::vector<NamedGradCheck> run_gradcheck_suite(unsigned seed = 7, const std::function<void(int, int)>& progress = {});

// The names of the ops the suite checks, in its order (the extreme-scale test in
// tests/autograd/ requires a row for each, so no op joins the suite without one).
std::vector<std::string> gradcheck_suite_ops();

}  // namespace ag

// The summary check printed by `gdsr demo`: every op of the library passes on random
// float64 inputs (tolerance 1e-6 relative, see gradcheck.hpp for the definition).
#include <doctest/doctest.h>

#include "autograd/gradcheck_suite.hpp"
#include "autograd/ops_elementwise.hpp"

TEST_CASE("gradcheck suite: every op passes at 1e-6 on random inputs") {
  int calls = 0;
  const auto results = ag::run_gradcheck_suite(11, [&](int done, int total) {
    ++calls;
    CHECK(done <= total);
  });
  CHECK(results.size() >= 40);
  CHECK(calls == static_cast<int>(results.size()));
  for (const auto& r : results) {
    INFO(r.op << ": " << r.result.report());
    CHECK(r.result.checked > 0);
    CHECK(r.passed());
  }
}

TEST_CASE("gradcheck: a wrong backward is caught") {
  // d/dx of x * x computed through a detached copy of one factor: half the true gradient.
  const auto r = ag::gradcheck([](const std::vector<ag::Tensord>& x) { return ag::mul(x[0], x[0].detach()); },
                               {ag::Tensord::from({2, 2}, {0.5, -1.0, 2.0, 1.5})});
  CHECK(r.max_rel_error > 0.4);
}

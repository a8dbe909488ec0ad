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

TEST_CASE("gradcheck: a planted 2x-wrong gradient is caught at input scales 1e-20 and 1e20") {
  // d/dx of x * detach(x) is x: half the true 2x. Correct ops at the same inputs pass.
  for (double s : {1e-20, 1e20}) {
    CAPTURE(s);
    const ag::Tensord x = ag::Tensord::from({2, 3}, {0.5 * s, -1.0 * s, 2.0 * s, 1.5 * s, -0.7 * s, 1.1 * s});
    const auto wrong =
        ag::gradcheck([](const std::vector<ag::Tensord>& in) { return ag::mul(in[0], in[0].detach()); }, {x});
    INFO(wrong.report());
    CHECK(wrong.max_rel_error > 0.4);
    const auto right = ag::gradcheck([](const std::vector<ag::Tensord>& in) { return ag::mul(in[0], in[0]); }, {x});
    CHECK_MESSAGE(right.max_rel_error < 1e-6, right.report());
    const auto smooth = ag::gradcheck(
        [s](const std::vector<ag::Tensord>& in) { return ag::tanh(ag::mul_scalar(in[0], 1.0 / s)); }, {x});
    CHECK_MESSAGE(smooth.max_rel_error < 1e-6, smooth.report());
  }
}

// The summary check printed by `gdsr demo`: every op of the library passes on random
// float64 inputs (tolerance 1e-6 relative, see gradcheck.hpp for the definition).
#include <doctest/doctest.h>

#include <cmath>

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

TEST_CASE("gradcheck: a planted 2x-wrong gradient is caught where the outputs sum beyond the largest double") {
  // x ~ 1e154: each x |x| is finite (~1e308) but sums of them are not. Summed in double, L
  // was inf, the difference quotient NaN, and every gradient failed, correct ones too.
  const double s = 1e154;
  for (const std::vector<double>& v :
       {std::vector<double>{0.9, 1.0, 1.2, 1.1, 0.95, 1.3}, std::vector<double>{0.9, -1.0, 1.2, -1.1, 0.95, -1.3}}) {
    std::vector<double> xs;
    for (double e : v) xs.push_back(e * s);
    const ag::Tensord x = ag::Tensord::from({2, 3}, xs);
    CAPTURE(v[1]);
    // d/dx x |x| = 2 |x|; through a detached |x| it is |x|.
    const auto wrong =
        ag::gradcheck([](const std::vector<ag::Tensord>& in) { return ag::mul(in[0], ag::abs(in[0]).detach()); }, {x});
    CHECK_MESSAGE(wrong.max_rel_error > 0.4, wrong.report());
    CHECK(std::isfinite(wrong.numeric));
    const auto right =
        ag::gradcheck([](const std::vector<ag::Tensord>& in) { return ag::mul(in[0], ag::abs(in[0])); }, {x});
    CHECK_MESSAGE(right.max_rel_error < 1e-6, right.report());
  }
}

TEST_CASE("gradcheck: per_column judges each column at its own scale") {
  // Column 0 ~ 1, column 1 ~ 1e-6, each curved on its own scale: one step for the whole input
  // (1e-6 x the largest entry) is as large as the small column itself, per column it is not.
  const ag::Tensord x = ag::Tensord::from({3, 2}, {0.5, 0.4e-6, -1.0, -0.9e-6, 0.8, 1.2e-6});
  const ag::Tensord k = ag::Tensord::from({1, 2}, {1.0, 1e6});
  auto f = [&](const std::vector<ag::Tensord>& in) { return ag::tanh(ag::mul(in[0], k)); };
  const auto whole = ag::gradcheck(f, {x});
  INFO(whole.report());
  CHECK(whole.max_rel_error > 1e-3);
  ag::GradCheckOptions opt;
  opt.per_column = true;
  const auto cols = ag::gradcheck(f, {x}, opt);
  INFO(cols.report());
  CHECK(cols.max_rel_error < 1e-6);
  CHECK(cols.checked == 6);
  // and a wrong gradient in the small column is still caught
  const ag::Tensord mask = ag::Tensord::from({1, 2}, {0.0, 1.0});
  const auto wrong = ag::gradcheck(
      [&](const std::vector<ag::Tensord>& in) {
        return ag::add(f(in), ag::mul(ag::mul(in[0], in[0].detach()), ag::mul_scalar(mask, 1e12)));
      },
      {x}, opt);
  INFO(wrong.report());
  CHECK(wrong.max_rel_error > 0.1);
  CHECK(wrong.element % 2 == 1);
}

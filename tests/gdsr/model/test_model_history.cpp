// The corrected history as tensors (gdsr::HistoryTensors, for `gdsr train --unroll`): the
// same output as from the history's values, the same training-noise draws, and a gradient
// with respect to C^_{t-1} and C^_{t-2} that checks in float64, carry included.
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/geometry_ad.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_config.hpp"
#include "tests/support/model_test_util.hpp"

#include <algorithm>
#include <cmath>
#include <string>

using namespace gdsr;

namespace {

double max_abs(const ag::Tensord& a, const ag::Tensord& b) {
  return (to_points(a) - to_points(b)).cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("model history: tensors give the values of the history they hold, and its gradient checks in float64") {
  for (const bool carry : {false, true}) {
    CAPTURE(carry);
    ModelConfig cfg = load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
    cfg.e_carry = carry;
    GDSR<double> model(cfg);
    if (carry) model.carry.values() = {0.4};
    const GarmentMesh garment = gdsr_test::two_layer_garment(3, 0.1, 0.01);
    const GarmentGraph g = build_graph(garment);
    nn::Rng rng(7);
    const FrameInput in = gdsr_test::make_frame(garment.V, rng, 0.004);
    const HrRequest hr = gdsr_test::random_samples(g.num_faces(), 12, rng);
    ag::Tensord h1 = ag::Tensord::from_eigen(in.Chat_tm1, true), h2 = ag::Tensord::from_eigen(in.Chat_tm2, true);
    const HistoryTensors<double> history{h1, h2};

    // Same values, with and without noise (the noise is drawn in the same order).
    const auto plain = model.forward(g, in, &hr);
    const auto with = model.forward(g, in, &hr, nullptr, nullptr, &history);
    CHECK(max_abs(plain.C_hat, with.C_hat) == 0.0);
    CHECK(max_abs(plain.G, with.G) == 0.0);
    cfg.noise_std = 0.003;
    GDSR<double> noisy(cfg);
    if (carry) noisy.carry.values() = {0.4};
    nn::Rng n1(3), n2(3), n3(4);
    const auto a = noisy.forward(g, in, &hr, &n1), b = noisy.forward(g, in, &hr, &n2, nullptr, &history);
    const auto c = noisy.forward(g, in, &hr, &n3, nullptr, &history);
    CHECK(max_abs(a.C_hat, b.C_hat) == 0.0);
    CHECK(max_abs(a.C_hat, c.C_hat) > 1e-6);  // the noise is there: another seed, another output

    // The history moves the output: a gradient that is zero would pass any check below.
    ag::sum(ag::concat_rows<double>({with.C_hat, with.G})).backward();
    double largest = 0;
    for (double v : h1.grad()) largest = std::max(largest, std::abs(v));
    CHECK(largest > 1e-3);
    h1.zero_grad(), h2.zero_grad();

    // Central differences in float64 with respect to both history frames. At the default
    // relative step 1e-6 (1e-7 m here) the worst entry was off by 6e-9 on a gradient of 9e-4:
    // round-off of the 108 summed outputs (~1e-16 x |L| / h). The history enters the node
    // features linearly, so a 10x larger step costs little truncation: tolerance 1e-6.
    const auto f = [&](const std::vector<ag::Tensord>& x) {
      const HistoryTensors<double> h{x[0], x[1]};
      const auto out = model.forward(g, in, &hr, nullptr, nullptr, &h);
      return ag::concat_rows<double>({out.C_hat, out.G});
    };
    ag::GradCheckOptions opt;
    opt.step = 1e-5;
    opt.abs_floor = 1e-3;  // gradients below it are judged by their absolute error (test_model_gradcheck.cpp)
    const ag::GradCheckResult r = ag::gradcheck(f, {h1, h2}, opt);
    MESSAGE("history (carry " << carry << "): " << r.report());
    CHECK(r.checked == 2 * 18 * 3);  // every entry of both frames
    CHECK(r.max_rel_error < 1e-6);
  }
}

TEST_CASE("model history: history tensors of the wrong shape are refused") {
  const ModelConfig cfg = load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
  const GDSR<double> model(cfg);
  const GarmentMesh garment = gdsr_test::two_layer_garment(3, 0.1, 0.01);
  const GarmentGraph g = build_graph(garment);
  nn::Rng rng(7);
  const FrameInput in = gdsr_test::make_frame(garment.V, rng, 0.004);
  const HistoryTensors<double> bad{ag::Tensord::zeros({5, 3}), ag::Tensord::from_eigen(in.Chat_tm2)};
  CHECK_THROWS_WITH_AS(model.forward(g, in, nullptr, nullptr, nullptr, &bad),
                       doctest::Contains("history tensors must be [18 x 3]"), gdsr::Error);
}

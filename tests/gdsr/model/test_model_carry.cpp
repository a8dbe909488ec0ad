// The carry of ModelConfig::e_carry: C^ = C + D + gamma (C^_{t-1} - C_{t-1}). At gamma = 0
// (its initial value) the model is the reference's; otherwise C^ moves by exactly gamma times
// the previous correction; gamma's gradient checks in float64.
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/geometry/geometry_ad.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_config.hpp"
#include "tests/support/model_test_util.hpp"

using namespace gdsr;

TEST_CASE("model carry: zero at the start, gamma times the previous correction, gradient checked") {
  ModelConfig cfg = load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
  const GDSR<double> plain(cfg);
  cfg.e_carry = true;
  GDSR<double> model(cfg);
  const GarmentMesh garment = gdsr_test::two_layer_garment(3, 0.1, 0.01);
  const GarmentGraph g = build_graph(garment);
  nn::Rng rng(5);
  const FrameInput in = gdsr_test::make_frame(garment.V, rng, 0.004);
  const Points3 d_prev = in.Chat_tm1 - in.C_tm1;
  REQUIRE(d_prev.cwiseAbs().maxCoeff() > 1e-3);

  // Registered after every other parameter: the same seed gives the same network, and gamma = 0.
  REQUIRE(model.carry.item() == 0.0);
  const Points3 c0 = to_points(model.forward(g, in, nullptr).C_hat);
  CHECK((c0 - to_points(plain.forward(g, in, nullptr).C_hat)).cwiseAbs().maxCoeff() == 0.0);

  model.carry.values() = {0.5};
  const Points3 c1 = to_points(model.forward(g, in, nullptr).C_hat);
  CHECK((c1 - c0 - 0.5 * d_prev).cwiseAbs().maxCoeff() < 1e-14);

  // With the correction switched off (ablation) there is no carry either: C^ = C.
  model.set_ablation({false, true});
  CHECK((to_points(model.forward(g, in, nullptr).C_hat) - in.C_t).cwiseAbs().maxCoeff() == 0.0);
  model.set_ablation({});

  // Central differences in float64; C^ is linear in gamma, so the step only meets round-off.
  const auto r = ag::gradcheck([&](const std::vector<ag::Tensord>&) { return model.forward(g, in, nullptr).C_hat; },
                               {model.carry});
  MESSAGE("carry: " << r.report());
  CHECK(r.max_rel_error < 1e-6);
}

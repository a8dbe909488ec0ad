// Roll-out (paper 3, 4.6) of an untrained tiny model on the synthetic waving sheet: every
// frame and every HR vertex is predicted, finite, and no body query is made without a body.
#include <doctest/doctest.h>

#include "gdsr/model/model_config.hpp"
#include "infer/rollout.hpp"
#include "tests/support/data_fixtures.hpp"

TEST_CASE("rollout: all frames and HR vertices of an untrained tiny model, finite, no body query") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(6);
  const gdsr::GDSR<float> model(gdsr::load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json"));
  const gdsr::RolloutResult ro = gdsr::rollout(model, d);
  REQUIRE(ro.G.size() == d.hr_frames.size());
  REQUIRE(ro.C_hat.size() == d.lr_frames.size());
  CHECK(ro.G[0].rows() == d.hr.V.rows());
  CHECK(ro.C_hat[3].rows() == d.lr.V.rows());
  for (const auto& G : ro.G) CHECK(G.allFinite());
  CHECK_FALSE(ro.collisions[0].body_queried);  // no body in this dataset: no query

  gdsr::RolloutOptions part;
  part.first_frame = 2;
  part.frames = 3;
  const gdsr::RolloutResult ro2 = gdsr::rollout(model, d, part);
  CHECK(ro2.first_frame == 2);
  CHECK(ro2.G.size() == 3);
}

// Roll-out (paper 3, 4.6) of an untrained tiny model on the synthetic waving sheet: every
// frame and every HR vertex is predicted, finite, and no body query is made without a body.
#include <doctest/doctest.h>

#include "gdsr/data/frame_input.hpp"
#include "gdsr/geometry/geometry_ad.hpp"
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

TEST_CASE("rollout: a roll-out from a later frame starts from the LR simulation, and E alone gives the same C^") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(7);
  const gdsr::GDSR<float> model(gdsr::load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json"));
  gdsr::RolloutOptions part;
  part.first_frame = 3;
  part.frames = 4;
  part.collisions = false;
  const gdsr::RolloutResult ro = gdsr::rollout(model, d, part);
  // The training's push-forward history: the same frames without the HR request.
  const std::vector<gdsr::Points3> pred = gdsr::corrected_rollout(model, gdsr::build_graph(d.lr), d, nullptr, 3, 4);
  REQUIRE(pred.size() == ro.C_hat.size());
  for (size_t k = 0; k < pred.size(); ++k) {
    CHECK((pred[k] - ro.C_hat[k]).cwiseAbs().maxCoeff() == 0.0);  // E does not depend on A
    CHECK((pred[k] - d.lr_frames[3 + k]).norm() > 0);                 // and it did correct the frame
  }
  // History before the first prediction is the LR simulation at t-1 and t-2 (d = 0) ...
  CHECK(&gdsr::rollout_history(d, pred, 3, 3, 1) == &d.lr_frames[2]);
  CHECK(&gdsr::rollout_history(d, pred, 3, 3, 2) == &d.lr_frames[1]);
  CHECK(&gdsr::rollout_history(d, pred, 3, 4, 2) == &d.lr_frames[2]);  // not frame 3: that is t-1
  // ... then the predictions; a frame not predicted yet is an error, not a silent stand-in.
  CHECK(&gdsr::rollout_history(d, pred, 3, 4, 1) == &pred[0]);
  CHECK(&gdsr::rollout_history(d, pred, 3, 6, 2) == &pred[1]);
  CHECK(&gdsr::rollout_history(d, pred, 0, 0, 2) == &d.lr_frames[0]);  // clamped at the start
  CHECK_THROWS_WITH_AS(gdsr::rollout_history(d, pred, 3, 9, 1), doctest::Contains("has not been predicted"),
                       std::runtime_error);
  // Training's push-forward may start from another history (the downsampled truth): frames
  // before `first` come from it, the predicted ones from the roll-out.
  std::vector<gdsr::Points3> truth;
  for (const auto& hr : d.hr_frames) truth.push_back(gdsr::downsample(d.corr, hr));
  CHECK(&gdsr::rollout_history(d, pred, 3, 4, 2, &truth) == &truth[2]);
  CHECK(&gdsr::rollout_history(d, pred, 3, 4, 1, &truth) == &pred[0]);
  const std::vector<gdsr::Points3> from_truth =
      gdsr::corrected_rollout(model, gdsr::build_graph(d.lr), d, nullptr, 3, 4, &truth);
  const gdsr::FrameInput in3 = gdsr::make_frame_input(d, 3, truth[2], truth[1], nullptr);
  CHECK((from_truth[0] - gdsr::to_points(model.forward(gdsr::build_graph(d.lr), in3, nullptr).C_hat))
            .cwiseAbs()
            .maxCoeff() == 0.0);
  CHECK((from_truth[0] - pred[0]).cwiseAbs().maxCoeff() > 0.0);
  const std::vector<gdsr::Points3> short_history(truth.begin(), truth.begin() + 2);
  CHECK_THROWS_WITH_AS(gdsr::rollout_history(d, pred, 3, 3, 1, &short_history), doctest::Contains("has 2 frames"),
                       std::runtime_error);
}

TEST_CASE("rollout: ablations switch E (C^ = C) or A (G = upsampled C^) off, and nothing else") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(5);
  gdsr::GDSR<float> model(gdsr::load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json"));
  gdsr::RolloutOptions o;
  o.collisions = false;
  const gdsr::RolloutResult full = gdsr::rollout(model, d, o);
  model.set_ablation({false, true});
  const gdsr::RolloutResult no_e = gdsr::rollout(model, d, o);
  model.set_ablation({true, false});
  const gdsr::RolloutResult no_a = gdsr::rollout(model, d, o);
  model.set_ablation({});
  const gdsr::RolloutResult again = gdsr::rollout(model, d, o);
  for (size_t k = 0; k < d.lr_frames.size(); ++k) {
    // No correction: C^ is the LR frame (to float rounding; the model runs in float).
    CHECK((no_e.C_hat[k] - d.lr_frames[k]).cwiseAbs().maxCoeff() < 1e-7);
    CHECK((full.C_hat[k] - d.lr_frames[k]).cwiseAbs().maxCoeff() > 1e-5);
    // No detail: the HR frame is the upsampled corrected frame (float upsample against double).
    CHECK((no_a.G[k] - gdsr::upsample(d.corr, no_a.C_hat[k])).cwiseAbs().maxCoeff() < 1e-6);
    CHECK((full.G[k] - gdsr::upsample(d.corr, full.C_hat[k])).cwiseAbs().maxCoeff() > 1e-6);
    CHECK((no_a.C_hat[k] - full.C_hat[k]).cwiseAbs().maxCoeff() == 0.0);  // E untouched by switching A off
    CHECK((again.G[k] - full.G[k]).cwiseAbs().maxCoeff() == 0.0);         // switched back on: as before
  }
}

TEST_CASE("rollout: the mean moves of E and A are |C^ - C| and |G - upsampled C^|, zero when switched off") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(5);
  gdsr::GDSR<float> model(gdsr::load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json"));
  gdsr::RolloutOptions o;
  o.collisions = false;  // G is then upsampled C^ + A's residual exactly
  const gdsr::RolloutResult full = gdsr::rollout(model, d, o);
  double e = 0, a = 0;
  const double T = static_cast<double>(d.lr_frames.size());
  for (size_t k = 0; k < d.lr_frames.size(); ++k) {
    e += (full.C_hat[k] - d.lr_frames[k]).rowwise().norm().mean() / T;
    a += (full.G[k] - gdsr::upsample(d.corr, full.C_hat[k])).rowwise().norm().mean() / T;
  }
  CHECK(e > 1e-5);
  CHECK(a > 1e-6);
  CHECK(full.mean_correction == doctest::Approx(e).epsilon(1e-4));
  CHECK(full.mean_detail == doctest::Approx(a).epsilon(1e-3));  // float G against a double upsample
  model.set_ablation({false, false});
  const gdsr::RolloutResult none = gdsr::rollout(model, d, o);
  CHECK(none.mean_correction == 0.0);
  CHECK(none.mean_detail == 0.0);
}

TEST_CASE("rollout: --true-history feeds every frame the downsampled HR simulation as its history") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(7);
  const gdsr::GDSR<float> model(gdsr::load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json"));
  const gdsr::GarmentGraph g = gdsr::build_graph(d.lr);
  gdsr::RolloutOptions o;
  o.collisions = false;
  o.first_frame = 2;
  const gdsr::RolloutResult own = gdsr::rollout(model, d, o);
  o.true_history = true;
  const gdsr::RolloutResult taught = gdsr::rollout(model, d, o);
  REQUIRE(taught.C_hat.size() == 5);
  std::vector<gdsr::Points3> truth;
  for (const auto& hr : d.hr_frames) truth.push_back(gdsr::downsample(d.corr, hr));
  for (int k = 0; k < 5; ++k) {
    CAPTURE(k);
    const int t = 2 + k;
    const gdsr::FrameInput in = gdsr::make_frame_input(d, t, truth[t - 1], truth[t - 2], nullptr);
    CHECK((taught.C_hat[k] - gdsr::to_points(model.forward(g, in, nullptr).C_hat)).cwiseAbs().maxCoeff() == 0.0);
    CHECK((taught.C_hat[k] - own.C_hat[k]).cwiseAbs().maxCoeff() > 0.0);  // the model's own history differs
  }
  gdsr::Dataset no_hr = d;  // an own LR sequence has no HR frames
  no_hr.hr_frames.clear();
  CHECK_THROWS_WITH_AS(gdsr::rollout(model, no_hr, o), doctest::Contains("--true-history: needs the input's HR"),
                       std::runtime_error);
}

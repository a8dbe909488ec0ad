// Training loop on a tiny synthetic dataset (no simulator): the waving LR/HR sheet of
// tests/support/data_fixtures.hpp.
#include <doctest/doctest.h>

#include "tests/support/data_fixtures.hpp"
#include "tests/support/train_options.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_checkpoint.hpp"
#include "train/trainer.hpp"
#include "autograd/autograd.hpp"
#include "train/losses.hpp"
#include "gdsr/data/frame_input.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/geometry_ad.hpp"
#include "gdsr/geometry/uv_raster.hpp"
#include "nn/checkpoint.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <utility>
#include <vector>

const auto tiny_train_options = gdsr_test::tiny_train_options<gdsr::TrainOptions>;

TEST_CASE("trainer: the loss of a tiny model falls on a waving sheet, checkpoints reload") {
  const gdsr::Dataset d = gdsr_test::wave_dataset();
  gdsr_test::TempDir dir("trainer");
  gdsr::TrainOptions o = tiny_train_options();
  o.epochs = 60;  // 6 frames (t >= 2) per epoch
  o.checkpoint = dir / "model.ckpt";
  o.checkpoint_every = 50;
  // Positions only: with the reference weights the smoothness term (x100) dominates this
  // tiny sheet and the total plateaus; the switches are part of what is tested here.
  for (gdsr::LossTerm* t : {&o.loss.c_normal, &o.loss.c_strain, &o.loss.c_smooth, &o.loss.c_dihedral,
                            &o.loss.f_normal_map, &o.loss.f_strain, &o.loss.f_smooth})
    t->on = false;
  int logs = 0;
  std::map<std::string, double> first, last;  // unweighted terms summed over epoch 0 / the last epoch
  const gdsr::TrainResult r = gdsr::train_gdsr({&d}, o, [&](const gdsr::TrainLog& L) {
    ++logs;
    for (const auto& [k, v] : L.terms) {
      if (L.epoch == 0) first[k] += v;
      if (L.epoch == o.epochs - 1) last[k] += v;
    }
    CHECK(std::isfinite(L.loss));
    CHECK(L.terms.count("c_position") == 1);
    CHECK(L.terms.count("f_position") == 1);
    CHECK(L.terms.at("c_smooth") == 0.0);  // switched off: not computed
  });
  CHECK(r.steps == 360);
  CHECK(logs == 360);
  MESSAGE("loss first epoch " << r.first_epoch_mean << " -> last epoch " << r.last_epoch_mean);
  for (const auto& [k, v] : first) MESSAGE(k << ": " << v << " -> " << last[k]);
  CHECK(r.last_epoch_mean < 0.5 * r.first_epoch_mean);
  REQUIRE(std::filesystem::exists(o.checkpoint));
  const gdsr::ModelConfig cfg = gdsr::config_from_checkpoint(o.checkpoint);
  gdsr::GDSR<float> model(cfg);
  CHECK(nn::load_checkpoint<float>(o.checkpoint, model, nullptr).step == 360);
}

TEST_CASE("trainer: a NaN loss weight is refused and the last checkpoint kept") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(5);
  gdsr_test::TempDir dir("trainer_nan");
  gdsr::TrainOptions o = tiny_train_options();
  o.fine = false;
  o.checkpoint = dir / "model.ckpt";
  o.checkpoint_every = 1;
  o.max_steps = 2;
  gdsr::train_gdsr({&d}, o);
  REQUIRE(std::filesystem::exists(o.checkpoint));

  o.resume = o.checkpoint;
  o.max_steps = 5;
  o.loss.c_position.weight = std::nan("");
  CHECK_THROWS_WITH_AS(gdsr::train_gdsr({&d}, o), doctest::Contains("loss weight c_position must be finite"),
                       std::runtime_error);
  gdsr::GDSR<float> model(o.model);
  CHECK(nn::load_checkpoint<float>(o.checkpoint, model, nullptr).step == 2);  // the last good one
}

TEST_CASE("trainer: push-forward feeds the model its own history, and validation scores a roll-out") {
  const gdsr::Dataset d = gdsr_test::wave_dataset();
  gdsr::TrainOptions o = tiny_train_options();
  o.max_steps = 3;
  o.validation = {&d};
  o.checkpoint_every = 3;
  gdsr_test::TempDir dir("trainer_push_forward");
  auto first_step = [&](int K, bool from_truth = false) {
    o.rollout_history = K;
    o.rollout_from_truth = from_truth;
    o.checkpoint = dir / ("k" + std::to_string(K) + (from_truth ? "t" : "") + ".ckpt");
    std::vector<gdsr::TrainLog> logs;
    gdsr::train_gdsr({&d}, o, [&](const gdsr::TrainLog& L) { logs.push_back(L); });
    REQUIRE(logs.size() == 3);
    return logs;
  };
  const auto teacher = first_step(0), pushed = first_step(2), pushed_again = first_step(2),
             from_truth = first_step(2, true);
  CHECK(std::isfinite(pushed[0].loss));
  CHECK(std::isfinite(from_truth[0].loss));
  // The same frame and noise: only the history differs (the model's roll-out, not the HR truth;
  // with --rollout-from-truth, the roll-out starts from the truth instead of the LR input).
  CHECK(pushed[0].loss != teacher[0].loss);
  CHECK(from_truth[0].loss != teacher[0].loss);
  CHECK(from_truth[0].loss != pushed[0].loss);
  for (size_t i = 0; i < 3; ++i) CHECK(pushed[i].loss == pushed_again[i].loss);  // deterministic
  // Validation rolls each clip out from frame 0 with the model's own history, so both runs are
  // scored the same way, on finite figures, next to the upsampled LR yardstick.
  REQUIRE(pushed[2].validated);
  CHECK(std::isfinite(pushed[2].val_vertex_mm));
  CHECK(pushed[2].val_upsample_mm == teacher[2].val_upsample_mm);
  CHECK(pushed[2].val_upsample_mm > 0);
  // The same patches' normal maps: SSIM over garment pixels, in (0, 1], the yardstick the same.
  CHECK(pushed[2].val_ssim > 0);
  CHECK(pushed[2].val_ssim <= 1);
  CHECK(pushed[2].val_upsample_ssim == teacher[2].val_upsample_ssim);
  CHECK(pushed[2].val_upsample_ssim < 1);
}

TEST_CASE("trainer: --detail-target changes only the fine terms of a step, not the coarse ones") {
  const gdsr::Dataset d = gdsr_test::wave_dataset();
  gdsr::TrainOptions o = tiny_train_options();
  o.max_steps = 1;
  auto step = [&](bool detail) {
    o.detail_target = detail;
    gdsr::TrainLog out;
    gdsr::train_gdsr({&d}, o, [&](const gdsr::TrainLog& L) { out = L; });
    return out;
  };
  const gdsr::TrainLog hr = step(false), detail = step(true);
  CHECK(detail.terms.at("c_position") == hr.terms.at("c_position"));  // same frame, same model
  CHECK(std::isfinite(detail.terms.at("f_position")));
  CHECK(detail.terms.at("f_position") != hr.terms.at("f_position"));
}

// --unroll, checked against the same computation written here with the model's public API:
// the step of frame t scores the coarse loss of frames t0 = max(t - 2, 2) .. t (mean), frame
// t0 fed the downsampled truth as its history and each later frame the outputs before it as
// tensors, and its gradient comes back through that history (a detached history gives
// another gradient norm). The learning rate is too small to move a float weight, so every
// step of the epoch sees the initial model and each frame's loss can be recomputed.
TEST_CASE("trainer: --unroll scores frames t-K+1..t and backpropagates through the history they pass on") {
  const gdsr::Dataset d = gdsr_test::wave_dataset();  // 8 frames: training frames 2..7
  gdsr::TrainOptions o = tiny_train_options();
  o.fine = false;
  o.model.noise_std = 0;
  o.lr = 1e-30;
  o.lr_floor = 0;  // (the default floor, 1e-6, would move the weights)
  o.weight_decay = 0;
  o.max_steps = 6;  // one epoch: each training frame once
  o.unroll = 3;
  std::vector<gdsr::TrainLog> logs;
  gdsr::train_gdsr({&d}, o, [&](const gdsr::TrainLog& L) { logs.push_back(L); });
  REQUIRE(logs.size() == 6);

  const gdsr::GDSR<float> model(o.model);  // the trainer's initial model (same config and seed)
  const gdsr::GarmentGraph g = gdsr::build_graph(d.lr);
  const gdsr::MeshTopology topo = gdsr::make_topology(d.lr);
  std::vector<gdsr::Points3> truth;
  for (const gdsr::Points3& h : d.hr_frames) truth.push_back(gdsr::downsample(d.corr, h));
  // (loss, gradient norm) of frame t; detach: each history as a constant, not a tensor.
  auto expected = [&](int t, bool detach, int K = 3) {
    const int t0 = std::max(t - K + 1, 2);
    gdsr::Points3 h1 = truth[t0 - 1], h2 = truth[t0 - 2];
    gdsr::HistoryTensors<float> hist{gdsr::to_tensor<float>(h1), gdsr::to_tensor<float>(h2)};
    ag::Tensorf sum;
    for (int k = t0; k <= t; ++k) {
      const gdsr::FrameInput in = gdsr::make_frame_input(d, k, h1, h2, nullptr);
      const auto out = model.forward(g, in, nullptr, nullptr, nullptr, detach ? nullptr : &hist);
      const ag::Tensorf c = gdsr::coarse_loss(o.loss, topo, out.C_hat, truth[k]).total;
      sum = k == t0 ? c : ag::add(sum, c);
      h2 = h1;
      h1 = gdsr::to_points(out.C_hat);
      hist = gdsr::HistoryTensors<float>{out.C_hat, hist.Chat_tm1};
    }
    const ag::Tensorf loss = ag::mul_scalar(sum, 1.0f / static_cast<float>(t - t0 + 1));
    loss.backward();
    double norm2 = 0;
    for (const auto& [name, p] : model.named_parameters()) {
      if (p.has_grad())
        for (float v : p.grad()) norm2 += static_cast<double>(v) * v;
      p.node().zero_grad();
    }
    return std::pair<double, double>{loss.item(), std::sqrt(norm2)};
  };
  std::vector<std::pair<double, double>> want, got;
  for (int t = 2; t < 8; ++t) want.push_back(expected(t, false));
  for (const gdsr::TrainLog& L : logs) got.push_back({L.loss, L.grad_norm});
  std::sort(want.begin(), want.end());
  std::sort(got.begin(), got.end());
  for (size_t i = 0; i < want.size(); ++i) {
    CAPTURE(i);
    CHECK(got[i].first == doctest::Approx(want[i].first).epsilon(1e-6).scale(0));
    CHECK(got[i].second == doctest::Approx(want[i].second).epsilon(1e-5).scale(0));
  }
  // What the checks above tell apart: frames 3..7 have earlier frames, and a history that is
  // not differentiated (or one frame's loss alone) gives other figures.
  for (int t = 3; t < 8; ++t) {
    CAPTURE(t);
    const auto [loss, norm] = expected(t, false);
    CHECK(std::abs(expected(t, true).second - norm) > 1e-3 * norm);
    CHECK(std::abs(expected(t, false, 1).first - loss) > 1e-3 * loss);
  }
  o.unroll = 0;
  CHECK_THROWS_WITH_AS(gdsr::train_gdsr({&d}, o), doctest::Contains("--unroll must be 1 (off) to 64"), gdsr::Error);
  o.unroll = 65;
  CHECK_THROWS_WITH_AS(gdsr::train_gdsr({&d}, o), doctest::Contains("--unroll must be 1 (off) to 64"), gdsr::Error);
}

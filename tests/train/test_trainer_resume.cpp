// Exact resume, checkpoint refusal and option guards of the trainer, on the waving sheet of
// tests/support/data_fixtures.hpp with the tiny model preset.
#include <doctest/doctest.h>

#include "gdsr/model/gdsr_model.hpp"
#include "nn/checkpoint.hpp"
#include "tests/support/data_fixtures.hpp"
#include "tests/support/train_options.hpp"
#include "train/trainer.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

namespace {

gdsr::TrainOptions resume_options() {
  gdsr::TrainOptions o = gdsr_test::tiny_train_options<gdsr::TrainOptions>();
  o.loss.schedule = true;
  o.lr_halve_every = 4;  // the lr schedule position matters in the resumed half
  o.epochs = 3;          // 6 frames per epoch; the lambda schedule moves every epoch
  o.loss.lambda_every_epochs = 1;
  o.checkpoint_every = 3;
  return o;
}

// All entries whose name starts with `prefix` (parameters, optimizer state), as raw bytes.
std::vector<nn::CheckpointEntry> entries(const std::string& path, const std::string& prefix) {
  std::vector<nn::CheckpointEntry> out;
  for (const auto& e : nn::read_checkpoint(path).entries)
    if (e.name.rfind(prefix, 0) == 0) out.push_back(e);
  return out;
}

void check_identical(const std::string& a, const std::string& b) {
  for (const char* prefix : {"param/", "adamw/"}) {
    const auto ea = entries(a, prefix), eb = entries(b, prefix);
    REQUIRE(ea.size() == eb.size());
    REQUIRE(!ea.empty());
    int differ = 0;
    for (size_t i = 0; i < ea.size(); ++i) {
      CHECK(ea[i].name == eb[i].name);
      differ += ea[i].bytes != eb[i].bytes;
    }
    CHECK_MESSAGE(differ == 0, std::string(prefix) << ": " << differ << " of " << ea.size() << " entries differ");
  }
}

std::vector<double> run(const std::vector<const gdsr::Dataset*>& data, const gdsr::TrainOptions& o) {
  std::vector<double> losses;
  gdsr::train_gdsr(data, o, [&](const gdsr::TrainLog& L) { losses.push_back(L.loss); });
  return losses;
}

// N steps in one go vs N/2 steps, a second trainer resumed from the checkpoint, N/2 more.
void check_exact_resume(gdsr::TrainOptions o, int64_t n, int64_t stop) {
  const gdsr::Dataset d = gdsr_test::wave_dataset();
  gdsr_test::TempDir dir("trainer_resume");
  o.max_steps = n;
  o.checkpoint = dir / "whole.ckpt";
  const std::vector<double> whole = run({&d}, o);
  REQUIRE(static_cast<int64_t>(whole.size()) == n);

  o.checkpoint = dir / "part.ckpt";
  o.max_steps = stop;
  const std::vector<double> first = run({&d}, o);
  o.resume = o.checkpoint;
  o.max_steps = n;  // the run's total, not steps to add
  const std::vector<double> second = run({&d}, o);
  REQUIRE(static_cast<int64_t>(first.size()) == stop);
  REQUIRE(static_cast<int64_t>(second.size()) == n - stop);
  for (int64_t i = 0; i < n - stop; ++i) CHECK(second[static_cast<size_t>(i)] == whole[static_cast<size_t>(stop + i)]);
  CHECK(nn::read_checkpoint(o.checkpoint).step == n);
  check_identical(dir / "whole.ckpt", o.checkpoint);
}

}  // namespace

TEST_CASE("trainer: a run stopped mid-epoch and resumed is bit-identical to one run") {
  // 14 steps of one frame: the stop at step 7 is inside epoch 1 (6 frames per epoch), so the
  // resumed half needs the epoch's order, the patch and noise streams and the lr position.
  check_exact_resume(resume_options(), 14, 7);
}

TEST_CASE("trainer: resume with two frames per step is bit-identical to one run") {
  gdsr::TrainOptions o = resume_options();
  o.frames_per_step = 2;
  o.epochs = 4;
  check_exact_resume(o, 10, 5);  // step 5 ends at frame 10, inside epoch 1
}

TEST_CASE("trainer: resume with the push-forward history is bit-identical to one run") {
  gdsr::TrainOptions o = resume_options();
  o.rollout_history = 3;  // the unroll draws no random numbers and depends on the parameters only
  check_exact_resume(o, 8, 4);
}

TEST_CASE("trainer: resume with the small preset is bit-identical to one run") {
  // A model with wide layers: Eigen's vectorised reductions on its tensors rounded by heap
  // alignment, which differs between the first and the resumed trainer (autograd/aligned_new.cpp).
  gdsr::TrainOptions o = resume_options();
  o.model = gdsr::load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/small.json");
  o.fine = false;  // the coarse part holds the wide layers; keeps the test short
  check_exact_resume(o, 6, 3);
}

TEST_CASE("trainer: a corrupt or foreign resume checkpoint is refused naming the file") {
  const gdsr::Dataset d = gdsr_test::wave_dataset();
  gdsr_test::TempDir dir("trainer_corrupt");
  gdsr::TrainOptions o = resume_options();
  o.max_steps = 2;
  o.checkpoint = dir / "model.ckpt";
  gdsr::train_gdsr({&d}, o);
  std::vector<char> bytes;
  {
    std::ifstream in(o.checkpoint, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  REQUIRE(bytes.size() > 100);
  bytes[bytes.size() / 2] ^= 0x10;
  const std::string bad = dir / "flipped.ckpt";
  std::ofstream(bad, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  o.resume = bad;
  o.max_steps = 4;
  o.checkpoint = dir / "new.ckpt";
  CHECK_THROWS_WITH_AS(gdsr::train_gdsr({&d}, o), doctest::Contains("flipped.ckpt': checksum mismatch"),
                       std::runtime_error);
  CHECK_FALSE(std::filesystem::exists(o.checkpoint));

  // A model-only checkpoint (no data order or RNG state) cannot continue a run exactly.
  gdsr::GDSR<float> model(o.model);
  nn::save_checkpoint<float>(dir / "model_only.ckpt", model, nullptr, 2);
  o.resume = dir / "model_only.ckpt";
  CHECK_THROWS_WITH_AS(gdsr::train_gdsr({&d}, o), doctest::Contains("optimizer state"), std::runtime_error);

  // Another dataset: a longer clip, and another garment with the same frame count.
  const gdsr::Dataset longer = gdsr_test::wave_dataset(10);
  o.resume = dir / "model.ckpt";
  CHECK_THROWS_WITH_AS(gdsr::train_gdsr({&longer}, o), doctest::Contains("was trained on other data"),
                       std::runtime_error);
  gdsr::Dataset other = gdsr_test::wave_dataset();
  other.manifest.garment = "another_garment";
  CHECK_THROWS_WITH_AS(gdsr::train_gdsr({&other}, o), doctest::Contains("another_garment"), std::runtime_error);

  // Already at the end: nothing is trained and nothing is overwritten.
  o.max_steps = 2;
  CHECK_THROWS_WITH_AS(gdsr::train_gdsr({&d}, o), doctest::Contains("already at step 2 of 2"), std::runtime_error);
  CHECK_FALSE(std::filesystem::exists(o.checkpoint));
}

TEST_CASE("trainer: bad options are refused before anything is written") {
  const gdsr::Dataset d = gdsr_test::wave_dataset();
  gdsr_test::TempDir dir("trainer_guards");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    const char* what;
    std::function<void(gdsr::TrainOptions&)> set;
  };
  const std::vector<Case> cases = {
      {"--epochs must be positive, got 0", [](auto& o) { o.epochs = 0; }},
      {"--epochs must be positive, got -1", [](auto& o) { o.epochs = -1; }},
      {"--max-steps must be positive, got 0", [](auto& o) { o.max_steps = 0; }},
      {"--max-steps must be positive, got -3", [](auto& o) { o.max_steps = -3; }},
      {"--frames-per-step must be positive", [](auto& o) { o.frames_per_step = 0; }},
      {"--rollout-history must be 0 (teacher forcing) to 64 frames, got -1", [](auto& o) { o.rollout_history = -1; }},
      {"--rollout-history must be 0 (teacher forcing) to 64 frames, got 65", [](auto& o) { o.rollout_history = 65; }},
      {"--rollout-from-truth needs --rollout-history K > 0",
       [](auto& o) {
         o.rollout_history = 0;
         o.rollout_from_truth = true;
       }},
      {"--lr must be finite and > 0, got nan", [nan](auto& o) { o.lr = nan; }},
      {"--lr must be finite and > 0, got -1", [](auto& o) { o.lr = -1; }},
      {"--lr must be finite and > 0, got inf", [](auto& o) { o.lr = std::numeric_limits<double>::infinity(); }},
      {"loss weight c_smooth must be finite and >= 0", [](auto& o) { o.loss.c_smooth.weight = -1; }},
      {"loss weight f_position must be finite and >= 0", [nan](auto& o) { o.loss.f_position.weight = nan; }},
      {"loss weight lambda_c_start must be finite", [](auto& o) { o.loss.lambda_c_start = -0.5; }},
      {"fewer frames than one step",
       [](auto& o) {
         o.frames_per_step = 7;
         o.epochs = 1;
       }},
  };
  for (const Case& c : cases) {
    gdsr::TrainOptions o = resume_options();
    o.checkpoint = dir / "model.ckpt";
    c.set(o);
    CHECK_THROWS_WITH_AS(gdsr::train_gdsr({&d}, o), doctest::Contains(c.what), std::runtime_error);
    CHECK_FALSE(std::filesystem::exists(o.checkpoint));
  }
}

TEST_CASE("trainer: a NaN in each loss term stops training naming the term and keeps the last good checkpoint") {
  // Each term alone; NaN ground truth reaches every term through the teacher-forced history
  // (the prediction) or the target, from step 3 on. The checkpoint of step 2 must survive
  // byte for byte.
  const gdsr::Dataset clean = gdsr_test::wave_dataset();
  gdsr::Dataset poisoned = gdsr_test::wave_dataset();
  for (auto& f : poisoned.hr_frames) f.setConstant(std::numeric_limits<double>::quiet_NaN());
  gdsr_test::TempDir dir("trainer_nan_terms");
  const std::vector<std::string> names = {"c_position", "c_normal", "c_strain",   "c_smooth", "c_dihedral",
                                          "f_position", "f_image_l1", "f_strain", "f_smooth"};
  for (const std::string& name : names) {
    gdsr::TrainOptions o = resume_options();
    gdsr::LossConfig& c = o.loss;
    std::map<std::string, gdsr::LossTerm*> terms = {
        {"c_position", &c.c_position}, {"c_normal", &c.c_normal},     {"c_strain", &c.c_strain},
        {"c_smooth", &c.c_smooth},     {"c_dihedral", &c.c_dihedral}, {"f_position", &c.f_position},
        {"f_image_l1", &c.f_image_l1}, {"f_strain", &c.f_strain},     {"f_smooth", &c.f_smooth},
        {"f_vgg", &c.f_vgg}};
    for (auto& [k, t] : terms) t->on = k == name;
    c.f_normal_map.on = name == "f_image_l1";
    o.fine = name[0] == 'f';
    o.checkpoint = dir / (name + ".ckpt");
    o.checkpoint_every = 1;
    o.max_steps = 2;
    gdsr::train_gdsr({&clean}, o);
    std::ifstream in(o.checkpoint, std::ios::binary);
    const std::string before((std::istreambuf_iterator<char>(in)), {});

    o.resume = o.checkpoint;
    o.max_steps = 5;
    std::string message;
    try {
      gdsr::train_gdsr({&poisoned}, o);
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
    INFO("term " << name << ": " << message);
    CHECK(message.find("training stopped at step 3") != std::string::npos);
    CHECK(message.find("loss term " + name + " is NaN") != std::string::npos);
    CHECK(message.find("last good checkpoint: " + o.checkpoint) != std::string::npos);
    std::ifstream again(o.checkpoint, std::ios::binary);
    CHECK(std::string((std::istreambuf_iterator<char>(again)), {}) == before);
  }
}

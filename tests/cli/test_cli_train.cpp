// `gdsr train` as a user runs it: a run killed with SIGKILL and resumed with --resume ends
// bit-identical to an uninterrupted run; the run folder holds the CSV log, the loss curves
// and the configuration; bad flags and files give a one-line error before anything is written.
#include "nn/checkpoint.hpp"
#include "tests/support/cli_run.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>
#include <unistd.h>

using gdsr_test::check_one_line_error;
using gdsr_test::gdsr_run;
using gdsr_test::Run;
using gdsr_test::slurp;
using gdsr_test::TempDir;
namespace fs = std::filesystem;

namespace {

constexpr int kEpochs = 20;  // 6 frames per epoch: 120 steps

std::string train_args(const std::string& data, const std::string& out) {
  return "train --data '" + data + "' --config '" + GDSR_SOURCE_DIR + "/configs/tiny.json' --no-vgg --patches 2 " +
         "--patch-size 32 --lr 3e-3 --epochs " + std::to_string(kEpochs) +
         " --checkpoint-every 2 --log-every 0 --out '" + out + "'";
}

int64_t checkpoint_step(const std::string& path) {
  try {
    return nn::read_checkpoint(path).step;
  } catch (const std::exception&) {
    return -1;
  }
}

// Data rows of a train_log.csv (header dropped).
std::vector<std::string> csv_rows(const std::string& path) {
  std::istringstream in(slurp(path));
  std::vector<std::string> rows;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) rows.push_back(line);
  return rows;
}

std::string column(const std::string& row, int k) {
  std::istringstream in(row);
  std::string f;
  for (int i = 0; i <= k; ++i) std::getline(in, f, ',');
  return f;
}

}  // namespace

TEST_CASE("cli train: kill -9 mid-run then --resume is bit-identical to an uninterrupted run") {
  TempDir dir("cli_train_kill");
  const std::string data = dir / "wave";
  gdsr::write_dataset(data, gdsr_test::wave_dataset());
  const int total = 6 * kEpochs;

  const Run whole = gdsr_run(dir, train_args(data, dir / "whole"));
  REQUIRE(whole.status == 0);
  CHECK(checkpoint_step(dir / "whole/model.ckpt") == total);

  // The same run in the background, killed with SIGKILL once it has checkpointed a few steps.
  const std::string killed = dir / "killed";
  const std::string cmd = std::string("exec '") + GDSR_BINARY_DIR + "/gdsr' " + train_args(data, killed) + " >'" +
                          (dir / "k.out") + "' 2>'" + (dir / "k.err") + "'";
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int64_t at = -1;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    at = checkpoint_step(killed + "/model.ckpt");
    if (at >= 10) break;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  // Then a random moment later: inside a step, a checkpoint write or a log append.
  std::this_thread::sleep_for(std::chrono::microseconds(std::random_device{}() % 30000));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  REQUIRE(WIFSIGNALED(status));  // killed, not finished
  const int64_t kept = checkpoint_step(killed + "/model.ckpt");
  MESSAGE("saw checkpoint step " << at << ", killed; checkpoint on disk: step " << kept << " of " << total);
  REQUIRE(kept >= 10);
  REQUIRE(kept < total);

  const Run resumed = gdsr_run(dir, train_args(data, killed) + " --resume '" + killed + "/model.ckpt'");
  REQUIRE(resumed.status == 0);
  CHECK(resumed.out.find("trained " + std::to_string(total - kept) + " steps") != std::string::npos);
  const nn::Checkpoint a = nn::read_checkpoint(dir / "whole/model.ckpt");
  const nn::Checkpoint b = nn::read_checkpoint(killed + "/model.ckpt");
  CHECK(b.step == total);
  REQUIRE(a.entries.size() == b.entries.size());
  int differ = 0;
  for (size_t i = 0; i < a.entries.size(); ++i) differ += a.entries[i].bytes != b.entries[i].bytes;
  CHECK(differ == 0);  // parameters and AdamW state, bit for bit

  // The log of the resumed run has every step once, with the uninterrupted run's losses.
  const std::vector<std::string> ra = csv_rows(dir / "whole/train_log.csv"), rb = csv_rows(killed + "/train_log.csv");
  REQUIRE(static_cast<int>(ra.size()) == total);
  REQUIRE(static_cast<int>(rb.size()) == total);
  int losses_differ = 0;
  for (int i = 0; i < total; ++i) {
    CHECK(column(rb[static_cast<size_t>(i)], 0) == std::to_string(i + 1));
    losses_differ += column(ra[static_cast<size_t>(i)], 2) != column(rb[static_cast<size_t>(i)], 2);
  }
  CHECK(losses_differ == 0);
}

TEST_CASE("cli train: the run folder holds the CSV log and loss curves and configuration") {
  TempDir dir("cli_train_log");
  const std::string data = dir / "wave";
  gdsr::write_dataset(data, gdsr_test::wave_dataset());
  const std::string out = dir / "run";
  const Run r = gdsr_run(dir, "train --data '" + data + "' --val-data '" + data + "' --config '" + GDSR_SOURCE_DIR +
                                  "/configs/tiny.json' --no-vgg --patches 2 --patch-size 32 --epochs 4 " +
                                  "--frames-per-step 2 --checkpoint-every 3 --unroll 2 --out '" + out + "'");
  REQUIRE(r.status == 0);
  const std::vector<std::string> rows = csv_rows(out + "/train_log.csv");
  REQUIRE(rows.size() == 12);  // 24 frames, 2 per step
  const std::string header = slurp(out + "/train_log.csv").substr(0, slurp(out + "/train_log.csv").find('\n'));
  for (const char* c : {"c_position", "f_smooth", "lr", "lambda_c", "lambda_w", "grad_norm", "seconds", "val_loss"})
    CHECK(header.find(c) != std::string::npos);
  CHECK(!column(rows[2], 20).empty());  // step 3: a checkpoint, validated
  CHECK(column(rows[3], 20).empty());
  // vertex error of the roll-out and of the upsampled LR input, mm, on the patches
  CHECK(header.find("val_vertex_mm,val_upsample_mm") != std::string::npos);
  CHECK(std::stod(column(rows[2], 23)) > 0);
  CHECK(std::stod(column(rows[2], 24)) > 0);
  CHECK(column(rows[3], 23).empty());
  CHECK(header.find("val_upsample_mm,val_ssim,val_upsample_ssim") != std::string::npos);
  for (int c : {25, 26}) {  // normal-map SSIM of the patches, GDSR and the upsampled LR
    CHECK(std::stod(column(rows[2], c)) > 0);
    CHECK(std::stod(column(rows[2], c)) <= 1);
  }
  CHECK(r.out.find("normal-map SSIM") != std::string::npos);
  CHECK(r.out.find("validation at step 3: loss") != std::string::npos);
  CHECK(r.out.find("roll-out vertex error") != std::string::npos);
  CHECK(std::stod(column(rows[0], 18)) > 0);  // gradient norm
  CHECK(fs::file_size(out + "/loss_curves.png") > 5000);
  CHECK(fs::exists(out + "/model.best.ckpt"));
  const nlohmann::json cfg = nlohmann::json::parse(slurp(out + "/config.json"));
  CHECK(cfg.at("frames_per_step") == 2);
  CHECK(cfg.at("unroll") == 2);
  CHECK(cfg.at("model").at("mp_steps") == 2);  // the preset's values, not its file name alone
  CHECK(cfg.at("loss").at("coarse").at("smooth").at("weight") == 100.0);
  CHECK(cfg.at("command").at("val_data").size() == 1);
  fs::copy_file(out + "/loss_curves.png", fs::path(GDSR_BINARY_DIR) / "cli_train_loss_curves.png",
                fs::copy_options::overwrite_existing);  // kept to look at

  // A log row edited by hand (a step that is not a number) is dropped on --resume, not a crash.
  // The log is also put back into the form of a run made before the validation SSIM columns
  // (the last two): its rows are kept on --resume, padded.
  std::string log, line;
  std::istringstream lines(slurp(out + "/train_log.csv"));
  while (std::getline(lines, line)) {
    for (int k = 0; k < 2; ++k) line.erase(line.rfind(','));
    log += line + "\n";
  }
  log.replace(log.find('\n') + 1, 1, "x");
  std::ofstream(out + "/train_log.csv", std::ios::trunc) << log;
  const Run resumed =
      gdsr_run(dir, "train --data '" + data + "' --val-data '" + data + "' --config '" + GDSR_SOURCE_DIR +
                        "/configs/tiny.json' --no-vgg --patches 2 --patch-size 32 --epochs 5 " +
                        "--frames-per-step 2 --resume '" + out + "/model.ckpt' --out '" + out + "'");
  CHECK(resumed.status == 0);
  CHECK(resumed.err.find("stoll") == std::string::npos);
  const std::vector<std::string> kept = csv_rows(out + "/train_log.csv");
  REQUIRE(kept.size() == 14);                         // 11 kept, 3 new
  CHECK(column(kept[1], 20) == column(rows[2], 20));  // step 3's validation loss, kept
  CHECK(column(kept[1], 26).empty());                 // padded
}

TEST_CASE("cli train: bad flags and files give a one-line error and write nothing") {
  TempDir dir("cli_train_bad");
  const std::string data = dir / "wave";
  gdsr::write_dataset(data, gdsr_test::wave_dataset());
  const std::string out = dir / "out";
  const std::string base = "train --data '" + data + "' --config '" + GDSR_SOURCE_DIR +
                           "/configs/tiny.json' --no-vgg --patches 2 --patch-size 32 --out '" + out + "'";
  check_one_line_error(gdsr_run(dir, base + " --epochs 0"), "--epochs must be positive");
  check_one_line_error(gdsr_run(dir, base + " --epochs -1"), "--epochs must be positive");
  check_one_line_error(gdsr_run(dir, base + " --max-steps 0"), "--max-steps must be positive");
  check_one_line_error(gdsr_run(dir, base + " --max-steps -1"), "--max-steps must be positive");
  check_one_line_error(gdsr_run(dir, base + " --lr nan"), "--lr must be finite");
  check_one_line_error(gdsr_run(dir, base + " --lr -1"), "--lr must be finite");
  check_one_line_error(gdsr_run(dir, base + " --frames-per-step 0"), "--frames-per-step must be positive");
  check_one_line_error(gdsr_run(dir, base + " --unroll 0"), "--unroll must be 1 (off) to 64");
  check_one_line_error(gdsr_run(dir, base + " --epochs x"), "--epochs");
  {
    std::ofstream(dir / "neg.json") << R"({"coarse": {"smooth": {"weight": -1}}})";
    check_one_line_error(gdsr_run(dir, base + " --loss-config '" + (dir / "neg.json") + "'"), "weight");
    nlohmann::json j = nlohmann::json::parse(slurp(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json"));
    j["mp_stpes"] = 3;
    std::ofstream(dir / "typo.json") << j.dump();
    const std::string typo = "train --data '" + data + "' --config '" + (dir / "typo.json") + "' --out '" + out + "'";
    check_one_line_error(gdsr_run(dir, typo), "mp_stpes");
  }
  CHECK_FALSE(fs::exists(out));

  // A corrupt --resume names the file and leaves the run folder as it was.
  REQUIRE(gdsr_run(dir, base + " --max-steps 2").status == 0);
  const std::string log_before = slurp(out + "/train_log.csv");
  std::string bytes = slurp(out + "/model.ckpt");
  bytes[bytes.size() - 3] ^= 0x01;
  std::ofstream(dir / "bad.ckpt", std::ios::binary) << bytes;
  check_one_line_error(gdsr_run(dir, base + " --max-steps 4 --resume '" + (dir / "bad.ckpt") + "'"),
                       "bad.ckpt': checksum mismatch");
  CHECK(slurp(out + "/train_log.csv") == log_before);
  CHECK(nn::read_checkpoint(out + "/model.ckpt").step == 2);

  // A missing frame file of the dataset names the file.
  for (const auto& e : fs::directory_iterator(data))
    if (e.path().filename().string().find("hr_frames") != std::string::npos) fs::remove(e.path());
  check_one_line_error(gdsr_run(dir, base + " --max-steps 4"), "hr_frames");
  CHECK(nn::read_checkpoint(out + "/model.ckpt").step == 2);
}

TEST_CASE("cli weights: a run's weights alone load in infer with the same prediction and cannot be resumed") {
  TempDir dir("cli_weights");
  const std::string data = dir / "wave";
  gdsr::write_dataset(data, gdsr_test::wave_dataset());
  const std::string run = dir / "run";
  REQUIRE(gdsr_run(dir, "train --data '" + data + "' --config '" + GDSR_SOURCE_DIR +
                            "/configs/tiny.json' --no-vgg --patches 2 --patch-size 32 --max-steps 3 --rollout-history 2 " +
                            "--out '" + run + "'")
              .status == 0);
  const std::string weights = dir / "w.ckpt";
  const Run w = gdsr_run(dir, "weights --model '" + run + "/model.ckpt' --out '" + weights + "'");
  REQUIRE(w.status == 0);
  CHECK(w.out.find("at step 3") != std::string::npos);
  const nn::Checkpoint ck = nn::read_checkpoint(weights);
  CHECK(ck.step == 3);
  int params = 0;
  for (const auto& e : ck.entries) {
    CHECK(e.name.rfind("param/", 0) == 0);  // no optimizer state
    CHECK(e.dtype == nn::DType::F32);
    ++params;
  }
  CHECK(params > 0);
  CHECK(fs::file_size(weights) < fs::file_size(run + "/model.ckpt") / 2);
  for (const auto& [model, out] : {std::pair{run + "/model.ckpt", dir / "pa"}, std::pair{weights, dir / "pb"}})
    REQUIRE(gdsr_run(dir, "infer --model '" + model + "' --data '" + data + "' --out '" + out + "'").status == 0);
  CHECK(slurp(dir / "pa/pred_hr.bin") == slurp(dir / "pb/pred_hr.bin"));
  const Run resumed = gdsr_run(dir, "train --data '" + data + "' --config '" + GDSR_SOURCE_DIR +
                                        "/configs/tiny.json' --no-vgg --max-steps 4 --resume '" + weights +
                                        "' --out '" + run + "'");
  CHECK(resumed.status != 0);
  check_one_line_error(resumed, "w.ckpt");
}

TEST_CASE("cli train: --init fine-tunes from a model's weights with a fresh optimizer from step 0") {
  TempDir dir("cli_train_init");
  const std::string data = dir / "wave";
  gdsr::write_dataset(data, gdsr_test::wave_dataset());
  const std::string tiny = std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json";
  const std::string base = "train --data '" + data + "' --config '" + tiny + "' --no-vgg --patches 2 --patch-size 32 ";
  REQUIRE(gdsr_run(dir, base + "--max-steps 6 --lr 3e-3 --out '" + (dir / "first") + "'").status == 0);
  const std::string weights = "weights --model '" + (dir / "first/model.ckpt") + "' --out '" + (dir / "w.ckpt") + "'";
  REQUIRE(gdsr_run(dir, weights).status == 0);
  // Two steps at the smallest learning rate (the schedule's floor, 1e-6) move no weight by more
  // than ~2e-6 (AdamW's first steps are at most ~lr each): the fine-tuned run ends where its init
  // was, while the same two steps from a fresh model's random weights end ~0.1 away.
  const std::string tiny_steps = base + "--max-steps 2 --lr 1e-6 --out '";
  const Run tuned = gdsr_run(dir, tiny_steps + (dir / "tuned") + "' --init '" + (dir / "w.ckpt") + "'");
  REQUIRE(tuned.status == 0);
  CHECK(tuned.out.find("trained 2 steps") != std::string::npos);  // a new run: step 0, not the init's 6
  REQUIRE(gdsr_run(dir, tiny_steps + (dir / "fresh") + "'").status == 0);
  const nn::Checkpoint w = nn::read_checkpoint(dir / "w.ckpt");
  auto largest_difference = [&](const std::string& ckpt) {
    const nn::Checkpoint t = nn::read_checkpoint(ckpt);
    CHECK(t.step == 2);
    double largest = 0;
    for (const auto& e : w.entries) {
      REQUIRE(t.find(e.name));
      const std::vector<float> a = w.read<float>(e.name), b = t.read<float>(e.name);
      REQUIRE(a.size() == b.size());
      for (size_t i = 0; i < a.size(); ++i) largest = std::max(largest, static_cast<double>(std::abs(a[i] - b[i])));
    }
    return largest;
  };
  CHECK(largest_difference(dir / "tuned/model.ckpt") < 5e-6);
  CHECK(largest_difference(dir / "fresh/model.ckpt") > 1e-2);
  CHECK(nlohmann::json::parse(slurp(dir / "tuned/config.json")).at("init") == dir / "w.ckpt");
  // With --resume, or weights of another preset: a one-line error naming the problem.
  check_one_line_error(gdsr_run(dir, base + "--init '" + (dir / "w.ckpt") + "' --resume '" +
                                         (dir / "first/model.ckpt") + "' --out '" + (dir / "both") + "'"),
                       "--init");
  const std::string small = std::string(GDSR_SOURCE_DIR) + "/configs/small.json";
  check_one_line_error(gdsr_run(dir, "train --data '" + data + "' --config '" + small + "' --no-vgg --init '" +
                                         (dir / "w.ckpt") + "' --out '" + (dir / "other") + "'"),
                       "w.ckpt");
  check_one_line_error(gdsr_run(dir, base + "--init '" + (dir / "none.ckpt") + "' --out '" + (dir / "none") + "'"),
                       "none.ckpt");
  CHECK_FALSE(fs::exists(dir / "other"));
}

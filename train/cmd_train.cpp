// gdsr train: fit a GDSR model to one or more datasets (gdsr/trainer.hpp).
#include "gdsr/data/dataset.hpp"
#include "train/losses.hpp"
#include "gdsr/model/model_config.hpp"
#include "gdsr/cli/progress_bar.hpp"
#include "train/mpi_ranks.hpp"
#include "train/run_log.hpp"
#include "train/trainer.hpp"
#include "gdsr/cli/commands.hpp"

#include "gdsr/error.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

namespace {

struct TrainArgs {
  std::vector<std::string> data, val_data;
  std::string config = "configs/small.json";
  std::string loss_config;
  std::string out = "runs/gdsr";
  int log_every = 10;
  gdsr::TrainOptions opt;
  bool no_fine = false, no_vgg = false, no_schedule = false;
  bool max_steps_given = false;
};

// Every flag as given (or defaulted) plus the resolved presets, for config.json.
nlohmann::json command_json(const TrainArgs& a) {
  nlohmann::json j;
  j["data"] = a.data;
  j["val_data"] = a.val_data;
  j["config"] = a.config;
  j["loss_config"] = a.loss_config;
  j["out"] = a.out;
  j["log_every"] = a.log_every;
  j["no_fine"] = a.no_fine;
  j["no_vgg"] = a.no_vgg;
  j["no_schedule"] = a.no_schedule;
  return j;
}

void run_train(TrainArgs& a, const gdsr::MpiRanks& mpi) {
  a.opt.rank = mpi.rank();
  a.opt.ranks = mpi.size();
  if (mpi.size() > 1) a.opt.allreduce_sum = [&mpi](std::vector<double>& buf) { mpi.allreduce_sum(buf); };
  const bool writer = mpi.rank() == 0;  // rank 0 writes the checkpoints and logs and prints
  a.opt.model = gdsr::load_model_config(a.config);
  if (!a.loss_config.empty()) a.opt.loss = gdsr::load_loss_config(a.loss_config);
  if (a.no_schedule) a.opt.loss.schedule = false;
  a.opt.fine = !a.no_fine;
  a.opt.vgg = !a.no_vgg;
  if (a.max_steps_given && a.opt.max_steps <= 0)
    gdsr::fail("train", "--max-steps must be positive, got " + std::to_string(a.opt.max_steps));
  gdsr::validate_train_options(a.opt);  // before anything is read or written

  std::vector<gdsr::Dataset> sets, val_sets;
  for (const std::string& dir : a.data) sets.push_back(gdsr::load_dataset(dir));
  for (const std::string& dir : a.val_data) val_sets.push_back(gdsr::load_dataset(dir));
  std::vector<const gdsr::Dataset*> ptrs;
  for (const auto& s : sets) ptrs.push_back(&s);
  for (const auto& s : val_sets) a.opt.validation.push_back(&s);
  gdsr::check_init_weights(a.opt);  // weights of another preset are refused before the run folder is made
  const std::filesystem::path out(a.out);
  if (writer) {
    std::filesystem::create_directories(a.out);
    a.opt.checkpoint = (out / "model.ckpt").string();
    a.opt.best_checkpoint = (out / "model.best.ckpt").string();
  }
  if (writer && mpi.size() > 1)
    std::printf("%d ranks, %d frame(s) per rank and step\n", mpi.size(), a.opt.frames_per_step);
  for (const auto& s : sets)
    if (writer)
      std::printf("dataset %s: %d frames, LR %d / HR %d vertices, %d layer(s)%s\n", s.manifest.garment.c_str(),
                s.manifest.frames, s.manifest.lr_vertices, s.manifest.hr_vertices, s.manifest.layers,
                s.has_body() ? ", body" : "");

  std::ostringstream silent;  // ranks other than 0 draw no progress
  gdsr::ProgressBar bar("train", writer ? nullptr : &silent);
  auto progress = bar.callback();
  // The run log starts with the first step, so a run refused at the start (bad data, a
  // corrupt --resume) leaves the folder's earlier log in place.
  std::unique_ptr<gdsr::RunLog> run_log;
  double allreduce_seconds = 0;
  const gdsr::TrainResult r = gdsr::train_gdsr(ptrs, a.opt, [&](const gdsr::TrainLog& L) {
    allreduce_seconds += L.allreduce_seconds;
    if (!writer) return;
    if (!run_log) {
      nlohmann::json cfg = gdsr::train_options_to_json(a.opt);
      cfg["command"] = command_json(a);
      gdsr::write_text_atomic((out / "config.json").string(), cfg.dump(2) + "\n");
      run_log = std::make_unique<gdsr::RunLog>(a.out, L.step - 1);
    }
    run_log->add(L);
    progress(static_cast<int>(L.step), static_cast<int>(L.total_steps));
    if (a.log_every > 0 && (L.step % a.log_every == 0 || L.step == 1 || L.step == L.total_steps)) {
      std::fprintf(stderr, "\n");
      std::printf("step %lld/%lld epoch %d loss %.5g (coarse %.4g, fine %.4g) lr %.2g %.2fs/step\n",
                  static_cast<long long>(L.step), static_cast<long long>(L.total_steps), L.epoch, L.loss, L.coarse,
                  L.fine, L.lr, L.seconds);
      std::fflush(stdout);
    }
    if (L.validated) {
      std::fprintf(stderr, "\n");
      std::printf(
          "validation at step %lld: loss %.5g; roll-out vertex error %.2f mm (upsampled LR %.2f mm), normal-map SSIM "
          "%.4f (upsampled LR %.4f) on the patches\n",
          static_cast<long long>(L.step), L.val_loss, L.val_vertex_mm, L.val_upsample_mm, L.val_ssim,
          L.val_upsample_ssim);
      std::fflush(stdout);
    }
  });
  if (!writer) return;
  bar.finish();
  std::printf("trained %lld steps (%lld parameters), %.2f s/step; loss first epoch %.5g -> last epoch %.5g\n",
              static_cast<long long>(r.steps), static_cast<long long>(r.parameters), r.seconds_per_step,
              r.first_epoch_mean, r.last_epoch_mean);
  std::printf("checkpoint: %s (best: %s, %.5g)\n", r.checkpoint.c_str(), r.best_checkpoint.c_str(), r.best);
  if (mpi.size() > 1)
    std::printf("all-reduce: %.3g ms per step over %d ranks\n", 1e3 * allreduce_seconds / std::max<int64_t>(1, r.steps),
                mpi.size());
  std::printf("log: %s, %s, %s\n", run_log->csv_path().c_str(), run_log->png_path().c_str(),
              (out / "config.json").string().c_str());
}

}  // namespace

void add_train_command(CLI::App& app) {
  auto a = std::make_shared<TrainArgs>();
  CLI::App* c = app.add_subcommand("train", "train a GDSR model on paired LR/HR datasets");
  c->add_option("--data", a->data, "dataset folder (repeat for several)")->required();
  c->add_option("--config", a->config, "model preset (configs/*.json)")->capture_default_str();
  c->add_option("--loss-config", a->loss_config, "loss weights/switches JSON (default: reference weights)");
  c->add_option("--out", a->out, "run folder (model.ckpt is written there)")->capture_default_str();
  c->add_option("--epochs", a->opt.epochs, "passes over all frames")->capture_default_str();
  c->add_option("--val-data", a->val_data, "validation dataset folder (repeat for several), scored at checkpoints");
  c->add_option("--max-steps", a->opt.max_steps, "stop when the run reaches this many steps (resumes included)")
      ->each([a](const std::string&) { a->max_steps_given = true; });
  c->add_option("--frames-per-step", a->opt.frames_per_step, "frames whose gradients are averaged per step")
      ->capture_default_str();
  c->add_option("--rollout-history", a->opt.rollout_history,
                 "push-forward: the history of a training frame is the model's own roll-out over the K frames "
                 "before it (0: the downsampled HR truth, teacher forcing)")
      ->capture_default_str();
  c->add_option("--unroll", a->opt.unroll,
                "train through a roll-out: each training frame's loss also covers the K-1 frames before it, "
                "the history passed on with its gradient (1: off)")
      ->capture_default_str();
  c->add_flag("--rollout-from-truth", a->opt.rollout_from_truth,
              "the push-forward roll-out starts from the downsampled HR truth before it, not from the LR input "
              "(with --rollout-history)");
  c->add_flag("--detail-target", a->opt.detail_target,
              "fine loss against the HR frame's own detail on the model's coarse shape (default: the HR frame)");
  c->add_option("--lr", a->opt.lr, "AdamW learning rate")->capture_default_str();
  c->add_option("--lr-halve-every", a->opt.lr_halve_every, "halve the lr every N steps")->capture_default_str();
  c->add_option("--seed", a->opt.seed, "frame order, patches, noise")->capture_default_str();
  c->add_option("--checkpoint-every", a->opt.checkpoint_every, "steps between checkpoints")->capture_default_str();
  c->add_option("--resume", a->opt.resume, "continue a run exactly from its checkpoint (e.g. OUT/model.ckpt)");
  c->add_option("--init", a->opt.init,
                "start from this model's weights (a checkpoint of the same preset, e.g. models/*.ckpt): "
                "fine-tuning, fresh optimizer, step 0");
  c->add_option("--patches", a->opt.patches.count, "UV patches per step")->capture_default_str();
  c->add_option("--patch-size", a->opt.patches.size, "patch side in raster pixels")->capture_default_str();
  c->add_option("--log-every", a->log_every, "print a loss line every N steps")->capture_default_str();
  c->add_flag("--no-fine", a->no_fine, "coarse correction only (no patches, no hyper-net)");
  c->add_flag("--no-vgg", a->no_vgg, "drop the VGG term of the fine loss");
  c->add_flag("--no-schedule", a->no_schedule, "lambda_c = lambda_w = 1 from the start");
  c->callback([a]() {
    gdsr::MpiRanks mpi;
    if (mpi.size() == 1) return run_train(*a, mpi);
    try {
      run_train(*a, mpi);
    } catch (const std::exception& e) {  // one rank's error must end every rank
      std::fprintf(stderr, "gdsr: error: %s\n", e.what());
      mpi.abort_all();
    }
  });
}

// gdsr train: fit a GDSR model to one or more datasets (gdsr/trainer.hpp).
#include "gdsr/data/dataset.hpp"
#include "train/losses.hpp"
#include "gdsr/model/model_config.hpp"
#include "gdsr/cli/progress_bar.hpp"
#include "train/trainer.hpp"
#include "gdsr/cli/commands.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

namespace {

struct TrainArgs {
  std::vector<std::string> data;
  std::string config = "configs/small.json";
  std::string loss_config;
  std::string out = "runs/gdsr";
  int log_every = 10;
  gdsr::TrainOptions opt;
  bool no_fine = false, no_vgg = false, no_schedule = false;
};

void run_train(TrainArgs& a) {
  a.opt.model = gdsr::load_model_config(a.config);
  if (!a.loss_config.empty()) a.opt.loss = gdsr::load_loss_config(a.loss_config);
  if (a.no_schedule) a.opt.loss.schedule = false;
  a.opt.fine = !a.no_fine;
  a.opt.vgg = !a.no_vgg;
  std::filesystem::create_directories(a.out);
  a.opt.checkpoint = (std::filesystem::path(a.out) / "model.ckpt").string();

  std::vector<gdsr::Dataset> sets;
  for (const std::string& dir : a.data) sets.push_back(gdsr::load_dataset(dir));
  std::vector<const gdsr::Dataset*> ptrs;
  for (const auto& s : sets) ptrs.push_back(&s);
  for (const auto& s : sets)
    std::printf("dataset %s: %d frames, LR %d / HR %d vertices, %d layer(s)%s\n", s.manifest.garment.c_str(),
                s.manifest.frames, s.manifest.lr_vertices, s.manifest.hr_vertices, s.manifest.layers,
                s.has_body() ? ", body" : "");

  gdsr::ProgressBar bar("train");
  auto progress = bar.callback();
  const gdsr::TrainResult r = gdsr::train_gdsr(ptrs, a.opt, [&](const gdsr::TrainLog& L) {
    progress(static_cast<int>(L.step), static_cast<int>(L.total_steps));
    if (a.log_every > 0 && (L.step % a.log_every == 0 || L.step == 1 || L.step == L.total_steps)) {
      std::fprintf(stderr, "\n");
      std::printf("step %lld/%lld epoch %d loss %.5g (coarse %.4g, fine %.4g) lr %.2g %.2fs/step\n",
                  static_cast<long long>(L.step), static_cast<long long>(L.total_steps), L.epoch, L.loss, L.coarse,
                  L.fine, L.lr, L.seconds);
      std::fflush(stdout);
    }
  });
  bar.finish();
  std::printf("trained %lld steps (%lld parameters), %.2f s/step; loss first epoch %.5g -> last epoch %.5g\n",
              static_cast<long long>(r.steps), static_cast<long long>(r.parameters), r.seconds_per_step,
              r.first_epoch_mean, r.last_epoch_mean);
  std::printf("checkpoint: %s\n", r.checkpoint.c_str());
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
  c->add_option("--max-steps", a->opt.max_steps, "stop after this many steps")->capture_default_str();
  c->add_option("--lr", a->opt.lr, "AdamW learning rate")->capture_default_str();
  c->add_option("--lr-halve-every", a->opt.lr_halve_every, "halve the lr every N steps")->capture_default_str();
  c->add_option("--seed", a->opt.seed, "frame order, patches, noise")->capture_default_str();
  c->add_option("--checkpoint-every", a->opt.checkpoint_every, "steps between checkpoints")->capture_default_str();
  c->add_option("--resume", a->opt.resume, "continue from a checkpoint");
  c->add_option("--patches", a->opt.patches.count, "UV patches per step")->capture_default_str();
  c->add_option("--patch-size", a->opt.patches.size, "patch side in raster pixels")->capture_default_str();
  c->add_option("--log-every", a->log_every, "print a loss line every N steps")->capture_default_str();
  c->add_flag("--no-fine", a->no_fine, "coarse correction only (no patches, no hyper-net)");
  c->add_flag("--no-vgg", a->no_vgg, "drop the VGG term of the fine loss");
  c->add_flag("--no-schedule", a->no_schedule, "lambda_c = lambda_w = 1 from the start");
  c->callback([a]() { run_train(*a); });
}

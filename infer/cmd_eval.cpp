// gdsr eval: roll out a checkpoint (or load a prediction written by gdsr infer) and compare
// it with the HR simulation: vertex error, normal-map SSIM, stretch energies, against the
// plain upsampling of the LR input.
#include "gdsr/cli/commands.hpp"

#include "gdsr/error.hpp"
#include "gdsr/cli/progress_bar.hpp"
#include "infer/cmd_rollout_common.hpp"
#include "infer/evaluate.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

using gdsr_cli::RolloutArgs;

namespace {

void print_evaluation(const gdsr::Evaluation& e) {
  std::printf("evaluation over %zu frames (mean):\n", e.frames.size());
  std::printf("  vertex error      GDSR %.2f mm   | LR upsampled %.2f mm\n", 1e3 * e.mean.error, 1e3 * e.mean.error_lr);
  std::printf("  normal-map SSIM   GDSR %.4f      | LR upsampled %.4f\n", e.mean.ssim, e.mean.ssim_lr);
  std::printf("  stretch E_u/E_v/E_uv  GDSR %.4f / %.4f / %.4f | HR simulation %.4f / %.4f / %.4f\n",
              e.mean.energies.E_u, e.mean.energies.E_v, e.mean.energies.E_uv, e.truth.E_u, e.truth.E_v, e.truth.E_uv);
}

}  // namespace

void add_eval_command(CLI::App& app) {
  auto a = std::make_shared<RolloutArgs>();
  CLI::App* c = app.add_subcommand("eval", "roll out (or load a prediction) and compare with the HR simulation");
  auto* src = c->add_option_group("source");
  src->add_option("--model", a->model, "checkpoint: roll out now");
  src->add_option("--pred", a->pred, "folder written by gdsr infer");
  src->require_option(1);
  gdsr_cli::add_rollout_options(c, *a);
  c->add_option("--ssim-every", a->ssim_every, "SSIM on every k-th frame")->capture_default_str();
  c->callback([a]() {
    const gdsr::Dataset d = gdsr::load_dataset(a->data);
    std::vector<gdsr::Points3> G;
    int first = a->opt.first_frame;
    if (!a->model.empty()) {
      G = gdsr_cli::run_rollout(*a, d).G;
    } else {
      namespace fs = std::filesystem;
      G = gdsr::array_to_frames(gdsr::read_array((fs::path(a->pred) / "pred_hr.bin").string()), a->pred);
      const std::string meta = (fs::path(a->pred) / "prediction.json").string();
      std::ifstream in(meta);
      if (!in) gdsr::fail(meta, "cannot open (not a folder written by gdsr infer?)");
      try {
        first = nlohmann::json::parse(in).at("first_frame").get<int>();
      } catch (const nlohmann::json::exception& e) {
        gdsr::fail(meta, e.what());
      }
    }
    gdsr::ProgressBar bar("evaluate");
    const gdsr::Evaluation e = gdsr::evaluate(d, G, first, a->ssim_every, bar.callback());
    bar.finish();
    print_evaluation(e);
  });
}

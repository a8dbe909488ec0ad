// gdsr infer: roll out a trained model over a dataset's LR sequence and write the predicted
// HR frames (plus OBJs and a preview); gdsr eval: the same, compared with the HR simulation.
#include "gdsr/dataset.hpp"
#include "gdsr/evaluate.hpp"
#include "gdsr/gdsr_model.hpp"
#include "gdsr/obj_io.hpp"
#include "gdsr/progress.hpp"
#include "gdsr/render.hpp"
#include "gdsr/rollout.hpp"
#include "gdsr/trainer.hpp"
#include "nn/checkpoint.hpp"
#include "train/commands.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

namespace {

struct InferArgs {
  std::string model, data, out = "runs/infer", pred;
  gdsr::RolloutOptions opt;
  bool no_collisions = false;
  int obj_every = 0;
  int ssim_every = 1;
};

gdsr::RolloutResult run_rollout(const InferArgs& a, const gdsr::Dataset& d) {
  gdsr::GDSR<float> model(gdsr::config_from_checkpoint(a.model));
  nn::load_checkpoint<float>(a.model, model, nullptr);
  gdsr::RolloutOptions opt = a.opt;
  opt.collisions = !a.no_collisions;
  gdsr::ProgressBar bar("roll-out");
  gdsr::RolloutResult r = gdsr::rollout(model, d, opt, bar.callback());
  bar.finish();
  int pushed = 0;
  for (const auto& c : r.collisions) pushed += c.hr_body + c.hr_layer;
  std::printf("rolled out %zu frames: %.3f s/frame (model %.3f s), LR %lld -> HR %lld vertices, %d HR vertices "
              "moved by collision handling\n",
              r.G.size(), r.seconds_per_frame, r.model_seconds_per_frame,
              static_cast<long long>(d.lr_frames[0].rows()), static_cast<long long>(d.hr_frames[0].rows()), pushed);
  return r;
}

void write_prediction(const InferArgs& a, const gdsr::Dataset& d, const gdsr::RolloutResult& r) {
  namespace fs = std::filesystem;
  fs::create_directories(a.out);
  gdsr::write_array((fs::path(a.out) / "pred_hr.bin").string(), gdsr::frames_to_array(r.G));
  gdsr::write_array((fs::path(a.out) / "pred_lr.bin").string(), gdsr::frames_to_array(r.C_hat));
  nlohmann::json j{{"first_frame", r.first_frame}, {"frames", r.G.size()}, {"dataset", a.data},
                   {"model", a.model}, {"seconds_per_frame", r.seconds_per_frame}};
  gdsr::write_file_atomic((fs::path(a.out) / "prediction.json").string(), j.dump(2));
  if (a.obj_every > 0)
    for (size_t k = 0; k < r.G.size(); k += static_cast<size_t>(a.obj_every)) {
      gdsr::GarmentMesh m = d.hr;
      m.V = r.G[k];
      char name[64];
      std::snprintf(name, sizeof name, "hr_%05d.obj", r.first_frame + static_cast<int>(k));
      gdsr::write_obj((fs::path(a.out) / name).string(), m);
    }
  // Preview of the middle frame: LR input | GDSR | HR simulation.
  const size_t k = r.G.size() / 2;
  const int t = r.first_frame + static_cast<int>(k);
  const gdsr::TriMesh lr{d.lr_frames[t], d.lr.F}, pred{r.G[k], d.hr.F}, truth{d.hr_frames[t], d.hr.F};
  const cv::Mat img = gdsr::side_by_side({gdsr::render_meshes({lr}), gdsr::render_meshes({pred}),
                                          gdsr::render_meshes({truth})},
                                         {"LR input", "GDSR", "HR simulation"});
  gdsr::write_png_atomic((fs::path(a.out) / "preview.png").string(), img);
  std::printf("wrote %s (pred_hr.bin, pred_lr.bin, prediction.json, preview.png)\n", a.out.c_str());
}

void print_evaluation(const gdsr::Evaluation& e) {
  std::printf("evaluation over %zu frames (mean):\n", e.frames.size());
  std::printf("  vertex error      GDSR %.2f mm   | LR upsampled %.2f mm\n", 1e3 * e.mean.error, 1e3 * e.mean.error_lr);
  std::printf("  normal-map SSIM   GDSR %.4f      | LR upsampled %.4f\n", e.mean.ssim, e.mean.ssim_lr);
  std::printf("  stretch E_u/E_v/E_uv  GDSR %.4f / %.4f / %.4f | HR simulation %.4f / %.4f / %.4f\n",
              e.mean.energies.Eu, e.mean.energies.Ev, e.mean.energies.Euv, e.truth.Eu, e.truth.Ev, e.truth.Euv);
}

void add_common(CLI::App* c, InferArgs& a) {
  c->add_option("--data", a.data, "dataset folder (LR input; HR for eval)")->required();
  c->add_option("--first", a.opt.first_frame, "first frame")->capture_default_str();
  c->add_option("--frames", a.opt.frames, "number of frames (-1: to the end)")->capture_default_str();
  c->add_flag("--no-collisions", a.no_collisions, "skip the explicit collision handling");
}

}  // namespace

void add_infer_command(CLI::App& app) {
  auto a = std::make_shared<InferArgs>();
  CLI::App* c = app.add_subcommand("infer", "roll out a trained model on a dataset's LR sequence");
  c->add_option("--model", a->model, "checkpoint written by gdsr train")->required();
  add_common(c, *a);
  c->add_option("--out", a->out, "output folder")->capture_default_str();
  c->add_option("--obj-every", a->obj_every, "also write every k-th HR frame as OBJ (0: none)")->capture_default_str();
  c->callback([a]() {
    const gdsr::Dataset d = gdsr::load_dataset(a->data);
    write_prediction(*a, d, run_rollout(*a, d));
  });
}

void add_eval_command(CLI::App& app) {
  auto a = std::make_shared<InferArgs>();
  CLI::App* c = app.add_subcommand("eval", "roll out (or load a prediction) and compare with the HR simulation");
  auto* src = c->add_option_group("source");
  src->add_option("--model", a->model, "checkpoint: roll out now");
  src->add_option("--pred", a->pred, "folder written by gdsr infer");
  src->require_option(1);
  add_common(c, *a);
  c->add_option("--ssim-every", a->ssim_every, "SSIM on every k-th frame")->capture_default_str();
  c->callback([a]() {
    const gdsr::Dataset d = gdsr::load_dataset(a->data);
    std::vector<gdsr::Points3> G;
    int first = a->opt.first_frame;
    if (!a->model.empty()) {
      G = run_rollout(*a, d).G;
    } else {
      namespace fs = std::filesystem;
      G = gdsr::array_to_frames(gdsr::read_array((fs::path(a->pred) / "pred_hr.bin").string()), a->pred);
      const std::string meta = (fs::path(a->pred) / "prediction.json").string();
      std::ifstream in(meta);
      if (!in) throw std::runtime_error(meta + ": cannot open (not a folder written by gdsr infer?)");
      try {
        first = nlohmann::json::parse(in).at("first_frame").get<int>();
      } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(meta + ": " + e.what());
      }
    }
    gdsr::ProgressBar bar("evaluate");
    const gdsr::Evaluation e = gdsr::evaluate(d, G, first, a->ssim_every, bar.callback());
    bar.finish();
    print_evaluation(e);
  });
}

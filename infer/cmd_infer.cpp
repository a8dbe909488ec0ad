// gdsr infer: roll out a trained model over an LR sequence (a dataset's, or the user's own
// per-frame OBJs with --lr-dir) and write the predicted HR frames (plus OBJs and a preview).
#include "gdsr/cli/commands.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/io/render.hpp"
#include "gdsr/io/staged_folder.hpp"
#include "infer/cmd_rollout_common.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>

using gdsr_cli::RolloutArgs;

namespace {

void write_prediction(const RolloutArgs& a, const gdsr::Dataset& d, const gdsr::RolloutResult& r) {
  namespace fs = std::filesystem;
  gdsr::StagedFolder out(a.out, "prediction.json");  // all files, or none
  gdsr::write_prediction(out.path(), gdsr_cli::to_prediction(a, r));
  if (a.obj_every > 0)
    for (size_t k = 0; k < r.G.size(); k += static_cast<size_t>(a.obj_every)) {
      gdsr::GarmentMesh m = d.hr;
      m.V = r.G[k];
      char name[64];
      std::snprintf(name, sizeof name, "hr_%05d.obj", r.first_frame + static_cast<int>(k));
      gdsr::write_obj((fs::path(out.path()) / name).string(), m);
    }
  // Preview of the middle frame: LR input | GDSR | HR simulation (when there is one).
  const size_t k = r.G.size() / 2;
  const int t = r.first_frame + static_cast<int>(k);
  const gdsr::TriMesh lr{d.lr_frames[t], d.lr.F}, pred{r.G[k], d.hr.F};
  std::vector<cv::Mat> panels{gdsr::render_meshes({lr}), gdsr::render_meshes({pred})};
  std::vector<std::string> labels{"LR input", "GDSR"};
  if (static_cast<int>(d.hr_frames.size()) > t) {
    panels.push_back(gdsr::render_meshes({gdsr::TriMesh{d.hr_frames[t], d.hr.F}}));
    labels.push_back("HR simulation");
  }
  const cv::Mat img = gdsr::side_by_side(panels, labels);
  gdsr::write_png_atomic((fs::path(out.path()) / "preview.png").string(), img);
  out.commit();
  std::printf("wrote %s (pred_hr.bin, pred_lr.bin, prediction.json, preview.png)\n", a.out.c_str());
}

}  // namespace

void add_infer_command(CLI::App& app) {
  auto a = std::make_shared<RolloutArgs>();
  CLI::App* c = app.add_subcommand(
      "infer",
      "roll out a trained model on an LR sequence: a dataset's (--data) or your own per-frame OBJs (--lr-dir)");
  c->add_option("--model", a->model, "checkpoint written by gdsr train")->required();
  gdsr_cli::add_rollout_options(c, *a, false);
  gdsr_cli::add_sequence_options(c, *a);
  c->add_option("--out", a->out, "output folder")->capture_default_str();
  c->add_option("--obj-every", a->obj_every, "also write every k-th HR frame as OBJ (0: none)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  c->callback([a]() {
    const gdsr::Dataset d = gdsr_cli::load_input(*a);
    write_prediction(*a, d, gdsr_cli::run_rollout(*a, d));
  });
}

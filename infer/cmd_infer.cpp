// gdsr infer: roll out a trained model over an LR sequence (a dataset's, or the user's own
// per-frame OBJs with --lr-dir) and write the predicted HR frames (plus OBJs and a preview).
#include "gdsr/cli/commands.hpp"
#include "gdsr/cli/progress_bar.hpp"
#include "gdsr/data/sequence_import.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/io/render.hpp"
#include "infer/cmd_rollout_common.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>

using gdsr_cli::RolloutArgs;

namespace {

void write_prediction(const RolloutArgs& a, const gdsr::Dataset& d, const gdsr::RolloutResult& r) {
  namespace fs = std::filesystem;
  gdsr::write_prediction(a.out, gdsr_cli::to_prediction(a, r));
  if (a.obj_every > 0)
    for (size_t k = 0; k < r.G.size(); k += static_cast<size_t>(a.obj_every)) {
      gdsr::GarmentMesh m = d.hr;
      m.V = r.G[k];
      char name[64];
      std::snprintf(name, sizeof name, "hr_%05d.obj", r.first_frame + static_cast<int>(k));
      gdsr::write_obj((fs::path(a.out) / name).string(), m);
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
  gdsr::write_png_atomic((fs::path(a.out) / "preview.png").string(), img);
  std::printf("wrote %s (pred_hr.bin, pred_lr.bin, prediction.json, preview.png)\n", a.out.c_str());
}

// The user's own LR sequence (--lr-dir ...) as a dataset without HR frames.
gdsr::Dataset import_user_sequence(const gdsr::SequenceImportOptions& s) {
  if (s.lr_uv.empty()) gdsr::fail("--lr-uv", "required with --lr-dir (the flattened LR pattern OBJ)");
  gdsr::SequenceImportOptions opt = s;
  gdsr::ProgressBar bar("read OBJs");
  opt.progress = bar.callback();
  gdsr::Dataset d = gdsr::import_lr_sequence(opt);
  bar.finish();
  std::printf("read %d frames: LR %d vertices, HR %d vertices (%s)\n", d.manifest.frames, d.manifest.lr_vertices,
              d.manifest.hr_vertices,
              s.hr_uv.empty() ? ("LR subdivided " + std::to_string(s.subdivide) + "x").c_str() : s.hr_uv.c_str());
  return d;
}

}  // namespace

void add_infer_command(CLI::App& app) {
  auto a = std::make_shared<RolloutArgs>();
  auto s = std::make_shared<gdsr::SequenceImportOptions>();
  CLI::App* c = app.add_subcommand(
      "infer",
      "roll out a trained model on an LR sequence: a dataset's (--data) or your own per-frame OBJs (--lr-dir)");
  c->add_option("--model", a->model, "checkpoint written by gdsr train")->required();
  gdsr_cli::add_rollout_options(c, *a, false);
  auto* own = c->add_option_group("own sequence", "your own LR simulation instead of --data");
  own->add_option("--lr-dir", s->lr_dir,
                  "folder of LR OBJs, one per frame (sorted by the number in the name; same faces in every frame)");
  own->add_option("--lr-uv", s->lr_uv, "flattened LR pattern OBJ (2-D layout in v, faces as the 3-D frames)");
  own->add_option("--hr-uv", s->hr_uv, "HR garment OBJ with v (3-D) and vt (pattern in the LR pattern's units)");
  own->add_option("--subdivide", s->subdivide, "without --hr-uv: HR = LR after 1 or 2 midpoint subdivisions")
      ->capture_default_str();
  own->add_option("--body-dir", s->body_dir, "folder of body OBJs, one per LR frame (optional)");
  own->add_option("--scale", s->scale, "file units -> metres (Marvelous Designer mm: 0.001)")->capture_default_str();
  own->add_option("--fps", s->fps, "frames per second of the OBJ sequence")->capture_default_str();
  c->add_option("--out", a->out, "output folder")->capture_default_str();
  c->add_option("--obj-every", a->obj_every, "also write every k-th HR frame as OBJ (0: none)")->capture_default_str();
  c->callback([a, s]() {
    if (a->data.empty() == s->lr_dir.empty()) gdsr::fail("infer", "give exactly one of --data and --lr-dir");
    if (!a->data.empty() && (!s->lr_uv.empty() || !s->hr_uv.empty() || !s->body_dir.empty()))
      gdsr::fail("infer", "--lr-uv, --hr-uv and --body-dir go with --lr-dir, not --data");
    if (!a->data.empty()) {
      const gdsr::Dataset d = gdsr::load_dataset(a->data);
      write_prediction(*a, d, gdsr_cli::run_rollout(*a, d));
      return;
    }
    const gdsr::Dataset d = import_user_sequence(*s);
    RolloutArgs named = *a;
    named.data = "lr-dir:" + s->lr_dir;
    write_prediction(named, d, gdsr_cli::run_rollout(named, d));
  });
}

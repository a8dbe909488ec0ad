#include "infer/cmd_rollout_common.hpp"

#include "gdsr/cli/progress_bar.hpp"
#include "gdsr/error.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_checkpoint.hpp"
#include "nn/checkpoint.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>

namespace gdsr_cli {

gdsr::RolloutResult run_rollout(const RolloutArgs& a, const gdsr::Dataset& d) {
  gdsr::GDSR<float> model(gdsr::config_from_checkpoint(a.model));
  nn::load_checkpoint<float>(a.model, model, nullptr);
  gdsr::GdsrAblation off;
  for (const std::string& part : a.ablate) (part == "correction" ? off.correction : off.detail) = false;
  model.set_ablation(off);
  gdsr::RolloutOptions opt = a.opt;
  opt.collisions = !a.no_collisions;
  opt.collision.sigma_b = gdsr::body_offset_for(d.manifest.sim_params, a.body_offset);
  opt.collision.sigma_l = gdsr::layer_offset_for(d.manifest.sim_params, a.layer_offset);
  opt.collision.hr_planes = !a.lr_planes;
  gdsr::ProgressBar bar("roll-out");
  gdsr::RolloutResult r = gdsr::rollout(model, d, opt, bar.callback());
  bar.finish();
  int pushed = 0;
  for (const auto& c : r.collisions) pushed += c.hr_body + c.hr_layer;
  char layers[64] = "";
  if (d.manifest.layers > 1)
    std::snprintf(layers, sizeof layers, ", layer offset %.1f mm", 1000 * opt.collision.sigma_l);
  std::printf(
      "rolled out %zu frames: %.3f s/frame (model %.3f s), LR %lld -> HR %lld vertices, %d HR vertices "
      "moved by collision handling (body offset %.1f mm%s)\n",
      r.G.size(), r.seconds_per_frame, r.model_seconds_per_frame, static_cast<long long>(d.lr.V.rows()),
      static_cast<long long>(d.hr.V.rows()), pushed, 1000 * opt.collision.sigma_b, layers);
  std::printf("  model parts: correction E moves LR vertices %.2f mm, detail A moves HR vertices %.2f mm (mean)\n",
              1000 * r.mean_correction, 1000 * r.mean_detail);
  return r;
}

void add_source_options(CLI::App* c, RolloutArgs& a) {
  auto* src = c->add_option_group("source");
  src->add_option("--model", a.model, "checkpoint: roll out now");
  src->add_option("--pred", a.pred, "folder written by gdsr infer");
  src->require_option(1);
}

namespace {
std::string canonical(const std::string& path) {
  std::error_code ec;
  if (path.empty()) return path;
  const std::filesystem::path abs = std::filesystem::absolute(path, ec);
  if (ec) return path;
  const std::filesystem::path p = std::filesystem::weakly_canonical(abs, ec);
  return ec ? abs.string() : p.string();
}
// What a prediction records as its input: the dataset folder, or "lr-dir:" and the OBJ folder
// of an own sequence, as absolute paths (eval and export compare it wherever they run).
std::string input_id(const RolloutArgs& a) {
  return a.data.empty() ? "lr-dir:" + canonical(a.seq.lr_dir) : canonical(a.data);
}
}  // namespace

gdsr::Prediction obtain_prediction(const RolloutArgs& a, const gdsr::Dataset& d) {
  if (a.model.empty()) {
    // A prediction has its own frames and dataset: both must match what is asked for.
    if (a.opt.first_frame != 0 || a.opt.frames != -1)
      gdsr::fail("--pred", "--first / --frames apply to --model; a prediction covers the frames it was made for");
    gdsr::Prediction p = gdsr::read_prediction(a.pred, true);
    if (!p.dataset.empty() &&
        (p.dataset.rfind("lr-dir:", 0) == 0 ? p.dataset : canonical(p.dataset)) != input_id(a))
      gdsr::fail("--pred", a.pred + " was made on " + p.dataset + ", not on " + input_id(a));
    const long long T = static_cast<long long>(d.lr_frames.size());  // an own sequence has no HR frames
    if (p.G.empty()) gdsr::fail("--pred", a.pred + " holds no frames");
    if (p.first_frame < 0 || p.first_frame + static_cast<long long>(p.G.size()) > T)
      gdsr::fail("--pred", a.pred + " covers frames " + std::to_string(p.first_frame) + ".." +
                               std::to_string(p.first_frame + static_cast<long long>(p.G.size()) - 1) + " but " +
                               a.data + " has " + std::to_string(T));
    for (size_t k = 0; k < p.G.size(); ++k)
      if (p.G[k].rows() != d.hr.V.rows())
        gdsr::fail("--pred", a.pred + " has " + std::to_string(p.G[k].rows()) + " HR vertices, " + a.data + " has " +
                                 std::to_string(d.hr.V.rows()));
    return p;
  }
  return to_prediction(a, run_rollout(a, d));
}

gdsr::Prediction to_prediction(const RolloutArgs& a, gdsr::RolloutResult r) {
  gdsr::Prediction p;
  p.first_frame = r.first_frame;
  p.G = std::move(r.G);
  p.C_hat = std::move(r.C_hat);
  p.dataset = input_id(a);
  p.model = a.model;
  for (const std::string& part : a.ablate) p.model += " (" + part + " off)";
  if (a.opt.true_history) p.model += " (true history)";
  p.seconds_per_frame = r.seconds_per_frame;
  p.model_seconds_per_frame = r.model_seconds_per_frame;
  return p;
}

void add_rollout_options(CLI::App* c, RolloutArgs& a, bool data_required) {
  auto* data = c->add_option("--data", a.data, "dataset folder (LR input; HR for eval)");
  if (data_required) data->required();
  c->add_option("--first", a.opt.first_frame, "first frame")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  c->add_option("--frames", a.opt.frames, "number of frames (-1: to the end)")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& s) {
            int n = 0;
            if (!CLI::detail::lexical_cast(s, n) || !(n == -1 || n >= 1))
              return "must be at least 1 (or -1: to the end), got " + s;
            return std::string();
          },
          "INT >= 1 or -1"));
  c->add_flag("--no-collisions", a.no_collisions, "skip the explicit collision handling");
  c->add_option("--body-offset", a.body_offset,
                "metres the collision handling keeps the HR garment off the body (default: the dataset's simulation "
                "thickness, else the paper's 0.015)")
      ->check(CLI::Range(0.0, 0.1));
  c->add_option("--layer-offset", a.layer_offset,
                "metres the collision handling keeps an outer layer off the layer under it (default: the dataset's "
                "simulation layer gap, else the paper's 0.020)")
      ->check(CLI::Range(0.0, 0.1));
  c->add_flag("--lr-planes,--lr-body-planes", a.lr_planes,
              "collision handling as in the paper: HR vertices pushed out of the tangent plane at their nearest LR "
              "vertex's body point or inner-layer vertex (default: each its own closest point, exact on a curved "
              "body or layer)");
  c->add_option("--ablate", a.ablate,
                "switch a part of the model off (repeatable): correction (C^ = C, no E) or detail (G = upsampled "
                "C^, no A)")
      ->check(CLI::IsMember({"correction", "detail"}));
  c->add_flag("--true-history", a.opt.true_history,
              "feed each frame the HR simulation downsampled to the LR mesh as its history instead of the model's "
              "own output (teacher forcing): how much the model gains when its history is right");
}

void add_sequence_options(CLI::App* c, RolloutArgs& a) {
  gdsr::SequenceImportOptions& s = a.seq;
  auto* own = c->add_option_group("own sequence", "your own LR simulation (per-frame OBJs) instead of --data");
  own->add_option("--lr-dir", s.lr_dir,
                  "folder of LR OBJs, one per frame (sorted by the number in the name; same faces in every frame)");
  own->add_option("--lr-uv", s.lr_uv, "flattened LR pattern OBJ (2-D layout in v, faces as the 3-D frames)");
  own->add_option("--hr-uv", s.hr_uv, "HR garment OBJ with v (3-D) and vt (pattern in the LR pattern's units)");
  own->add_option("--subdivide", s.subdivide, "without --hr-uv: HR = LR after 1 or 2 midpoint subdivisions")
      ->capture_default_str();
  own->add_option("--body-dir", s.body_dir, "folder of body OBJs, one per LR frame (optional)");
  own->add_option("--scale", s.scale, "file units -> metres (Marvelous Designer mm: 0.001)")->capture_default_str();
  own->add_option("--fps", s.fps, "frames per second of the OBJ sequence")->capture_default_str();
}

gdsr::Dataset load_input(const RolloutArgs& a) {
  const gdsr::SequenceImportOptions& s = a.seq;
  if (a.data.empty() == s.lr_dir.empty()) gdsr::fail("--data", "give exactly one of --data and --lr-dir");
  if (!a.data.empty()) {
    if (!s.lr_uv.empty() || !s.hr_uv.empty() || !s.body_dir.empty())
      gdsr::fail("--data", "--lr-uv, --hr-uv and --body-dir go with --lr-dir, not --data");
    return gdsr::load_dataset(a.data);
  }
  if (s.lr_uv.empty()) gdsr::fail("--lr-uv", "required with --lr-dir (the flattened LR pattern OBJ)");
  gdsr::SequenceImportOptions opt = s;
  gdsr::ProgressBar bar("read OBJs");
  opt.progress = bar.callback();
  gdsr::Dataset d = gdsr::import_lr_sequence(opt);
  bar.finish();
  const std::string hr = s.hr_uv.empty() ? "LR subdivided " + std::to_string(s.subdivide) + "x" : s.hr_uv;
  std::printf("read %d frames: LR %d vertices, HR %d vertices (%s)\n", d.manifest.frames, d.manifest.lr_vertices,
              d.manifest.hr_vertices, hr.c_str());
  return d;
}

}  // namespace gdsr_cli

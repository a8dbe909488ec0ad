// gdsr eval: roll out a checkpoint (or load a prediction written by gdsr infer) and compare
// it with the HR simulation: vertex error, normal-map SSIM, stretch energies, against the
// plain upsampling of the LR input.
#include "gdsr/cli/commands.hpp"

#include "gdsr/error.hpp"
#include "gdsr/cli/progress_bar.hpp"
#include "gdsr/io/staged_folder.hpp"
#include "infer/cmd_rollout_common.hpp"
#include "infer/evaluate.hpp"
#include "infer/export_rollout.hpp"
#include "infer/report.hpp"
#include "infer/report_viewer.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

namespace {

struct EvalArgs : gdsr_cli::RolloutArgs {
  std::string report;
  std::vector<int> image_steps;
  int video_every = 1;
  bool no_video = false, no_export = false, no_viewer = false;
};

// The report folder: tables, plots, images, video and (unless --no-export) glTF + PC2
// exports of the three sequences in DIR/export.
void write_report(const EvalArgs& a, const gdsr::Dataset& d, const gdsr::Prediction& p, const gdsr::Evaluation& e) {
  namespace fs = std::filesystem;
  gdsr::ReportOptions ro;
  ro.dataset_path = a.data;
  ro.image_steps = a.image_steps;
  ro.video = !a.no_video;
  ro.video_every = a.video_every;
  // The viewer needs the exports and three.js (npm, installed by scripts/setup.sh).
  const char* env = std::getenv("GDSR_VIEWER_DIR");
  const std::string viewer_src = env ? env : GDSR_VIEWER_DIR;
  const bool three = fs::exists(fs::path(viewer_src) / "node_modules/three/build/three.module.js");
  const bool viewer = !a.no_export && !a.no_viewer && three;
  if (!a.no_export && !a.no_viewer && !three)
    std::fprintf(stderr,
                 "gdsr: note: no viewer in the report: three.js is not installed in %s (run scripts/setup.sh)\n",
                 viewer_src.c_str());
  if (viewer)
    ro.extra_md.push_back(
        "## Viewer\n\n`viewer/index.html` plays LR input | GDSR | HR simulation side by side in a browser (orbit "
        "with the mouse, frame slider, normal-map toggle). Browsers load it over HTTP only: `python3 -m http.server "
        "-d " +
        a.report + " 8000`, then open http://localhost:8000/viewer/ (no network needed).\n");
  if (!a.no_export)
    ro.extra_md.push_back(
        "## Exports\n\n`export/`: the LR input (`lr`), the GDSR prediction (`gdsr`) and the HR simulation (`hr`) as "
        "glTF 2.0 with a morph-target animation (`NAME.gltf` + `NAME.bin`; Blender: File > Import > glTF 2.0, shading "
        "Smooth) and "
        "as a PC2 point cache on a rest OBJ (`NAME_rest.obj` + `NAME.pc2`; Blender: import the OBJ, add a Mesh "
        "Cache modifier, format PC2, frame start 0). See docs/exports.md. `export/export.json` lists them.\n");
  gdsr::StagedFolder out(a.report, "report.json");  // all files, or none
  // write_eval_report checks the steps first.
  const auto files = gdsr::write_eval_report(out.path(), d, p, e, ro);
  if (!a.no_export) {
    gdsr::RolloutExportOptions eo;
    eo.formats.obj = false;
    gdsr::export_rollout((fs::path(out.path()) / "export").string(), d, p.G, p.first_frame, eo);
  }
  if (viewer) gdsr::write_viewer(out.path(), viewer_src);
  out.commit();
  std::printf("wrote report %s: %zu files (report.md, report.json, plots/, images/%s%s%s)\n", a.report.c_str(),
              files.size(), a.no_video ? "" : ", rollout.avi", a.no_export ? "" : ", export/",
              viewer ? ", viewer/" : "");
}

void print_evaluation(const gdsr::Evaluation& e) {
  std::printf("evaluation over %zu frames (mean):\n", e.frames.size());
  std::printf("  vertex error      GDSR %.2f mm   | LR upsampled %.2f mm | HR at the LR scale %.2f mm\n",
              1e3 * e.mean.error, 1e3 * e.mean.error_lr, 1e3 * e.mean.error_scale);
  std::printf("  normal-map SSIM   GDSR %.4f      | LR upsampled %.4f    | HR at the LR scale %.4f\n", e.mean.ssim,
              e.mean.ssim_lr, e.mean.ssim_scale);
  std::printf("    garment pixels  GDSR %.4f      | LR upsampled %.4f    | HR at the LR scale %.4f\n",
              e.mean.ssim_garment, e.mean.ssim_garment_lr, e.mean.ssim_garment_scale);
  std::printf(
      "    (HR at the LR scale: the HR simulation downsampled and upsampled, what a perfect correction E\n"
      "     without detail would score; SSIM over the whole UV map counts its background, where both maps\n"
      "     are black, as 1: the garment-pixel line is the stricter figure)\n");
  std::printf("  stretch E_u/E_v/E_uv  GDSR %.4f / %.4f / %.4f | HR simulation %.4f / %.4f / %.4f\n",
              e.mean.energies.E_u, e.mean.energies.E_v, e.mean.energies.E_uv, e.truth.E_u, e.truth.E_v, e.truth.E_uv);
}

}  // namespace

void add_eval_command(CLI::App& app) {
  auto a = std::make_shared<EvalArgs>();
  CLI::App* c = app.add_subcommand("eval", "roll out (or load a prediction) and compare with the HR simulation");
  gdsr_cli::add_source_options(c, *a);
  gdsr_cli::add_rollout_options(c, *a);
  c->add_option("--ssim-every", a->ssim_every, "SSIM on every k-th frame")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  c->add_option("--report", a->report, "write a report folder: tables, plots, images, video, exports");
  c->add_option("--report-steps", a->image_steps,
                "roll-out steps (1 = first frame) with images (default: 1 50 100 500 last)")
      ->delimiter(',');
  c->add_option("--video-every", a->video_every, "report video: every k-th frame")->capture_default_str();
  c->add_flag("--no-video", a->no_video, "report without the video");
  c->add_flag("--no-export", a->no_export, "report without the glTF / PC2 exports (and the viewer)");
  c->add_flag("--no-viewer", a->no_viewer, "report without the browser viewer");
  c->callback([a]() {
    if (a->video_every < 1) gdsr::fail("--video-every", "must be at least 1");
    const gdsr::Dataset d = gdsr::load_dataset(a->data);
    const gdsr::Prediction p = gdsr_cli::obtain_prediction(*a, d);
    gdsr::ProgressBar bar("evaluate");
    const gdsr::Evaluation e = gdsr::evaluate(d, p.G, p.first_frame, a->ssim_every, bar.callback());
    bar.finish();
    print_evaluation(e);
    if (!a->report.empty()) write_report(*a, d, p, e);
  });
}

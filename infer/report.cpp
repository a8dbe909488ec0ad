#include "infer/report.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/io/render.hpp"
#include "infer/report_media.hpp"
#include "infer/report_tables.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>

namespace gdsr {

namespace {

nlohmann::json energies_json(const StrainEnergies& s) { return {{"E_u", s.E_u}, {"E_v", s.E_v}, {"E_uv", s.E_uv}}; }

nlohmann::json frame_json(const FrameEvaluation& f) {
  nlohmann::json j{{"frame", f.frame},
                   {"error_m", f.error},
                   {"error_lr_m", f.error_lr},
                   {"error_hr_lr_scale_m", f.error_scale},
                   {"energies", energies_json(f.energies)},
                   {"energies_lr", energies_json(f.energies_lr)},
                   {"energies_hr", energies_json(f.energies_hr)}};
  if (f.has_ssim) {
    j["ssim"] = f.ssim, j["ssim_lr"] = f.ssim_lr, j["ssim_hr_lr_scale"] = f.ssim_scale;
    j["ssim_garment"] = f.ssim_garment, j["ssim_garment_lr"] = f.ssim_garment_lr;
    j["ssim_garment_hr_lr_scale"] = f.ssim_garment_scale;
  }
  return j;
}

}  // namespace

std::vector<std::string> write_eval_report(const std::string& dir, const Dataset& d, const Prediction& p,
                                           const Evaluation& e, const ReportOptions& opt) {
  namespace fs = std::filesystem;
  const int n = static_cast<int>(e.frames.size());
  if (n == 0 || static_cast<int>(p.G.size()) != n)
    gdsr::fail(dir,
               "the evaluation covers " + std::to_string(n) + " frames, the prediction " + std::to_string(p.G.size()));
  std::vector<int> steps = opt.image_steps.empty() ? table_steps(n) : opt.image_steps;
  for (int s : steps)
    if (s < 1 || s > n)
      gdsr::fail(dir, "image step " + std::to_string(s) + " is outside the roll-out's 1.." + std::to_string(n));
  fs::create_directories(fs::path(dir) / "plots");
  fs::create_directories(fs::path(dir) / "images");
  std::vector<std::string> files;
  const auto png = [&](const std::string& rel, const cv::Mat& img) {
    write_png_atomic((fs::path(dir) / rel).string(), img);
    files.push_back(rel);
  };
  png("plots/error.png", plot_error(e));
  bool any_ssim = false;
  for (const auto& f : e.frames) any_ssim |= f.has_ssim;
  if (any_ssim) png("plots/ssim.png", plot_ssim(e));
  png("plots/energies.png", plot_energies(e));
  for (int s : steps) {
    char name[16];
    std::snprintf(name, sizeof name, "%05d", s);
    const int t = p.first_frame + s - 1;
    png(std::string("images/normals_") + name + ".png", normal_map_panel(d, p.G[s - 1], t));
    png(std::string("images/shaded_") + name + ".png", shaded_panel(d, p.G[s - 1], t));
  }
  ReportContext ctx;
  ctx.dataset_path = opt.dataset_path;
  ctx.image_steps = steps;
  std::string plots = "## Per-frame plots\n\n![vertex error](plots/error.png)\n\n";
  if (any_ssim) plots += "![normal-map SSIM](plots/ssim.png)\n\n";
  plots += "![energies](plots/energies.png)\n";
  ctx.extra_md.push_back(plots);
  if (opt.video) {
    const int frames =
        write_rollout_video((fs::path(dir) / "rollout.avi").string(), d, p.G, p.first_frame, opt.video_every);
    files.push_back("rollout.avi");
    ctx.extra_md.push_back("## Video\n\n[rollout.avi](rollout.avi): LR input | GDSR | HR simulation, " +
                           std::to_string(frames) + " frames (MJPG).\n");
  }
  for (const auto& x : opt.extra_md) ctx.extra_md.push_back(x);

  nlohmann::json j{{"garment", d.manifest.garment},
                   {"dataset", opt.dataset_path},
                   {"model", p.model},
                   {"first_frame", p.first_frame},
                   {"frames", n},
                   {"table_steps", table_steps(n)},
                   {"mean", frame_json(e.mean)},
                   {"seconds_per_frame", p.seconds_per_frame},
                   {"dataset_stats", d.manifest.stats}};
  j["mean"]["ssim"] = e.mean.ssim;
  j["mean"]["ssim_lr"] = e.mean.ssim_lr;
  j["mean"]["ssim_hr_lr_scale"] = e.mean.ssim_scale;
  j["mean"]["ssim_garment"] = e.mean.ssim_garment;
  j["mean"]["ssim_garment_lr"] = e.mean.ssim_garment_lr;
  j["mean"]["ssim_garment_hr_lr_scale"] = e.mean.ssim_garment_scale;
  for (const auto& f : e.frames) j["per_frame"].push_back(frame_json(f));
  write_file_atomic((fs::path(dir) / "report.json").string(), j.dump(1));
  files.push_back("report.json");
  write_file_atomic((fs::path(dir) / "report.md").string(), report_markdown(d, p, e, ctx));
  files.push_back("report.md");
  return files;
}

}  // namespace gdsr

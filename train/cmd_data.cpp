// gdsr data make | preview | import-md | check
#include "train/commands.hpp"

#include "gdsr/dataset.hpp"
#include "gdsr/md_import.hpp"
#include "gdsr/progress.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <memory>

namespace {

struct ImportArgs {
  gdsr::MdImportOptions opt;
  std::string out;
};

void run_import(const ImportArgs& a) {
  gdsr::MdImportOptions opt = a.opt;
  gdsr::ProgressBar bar("import");
  opt.progress = bar.callback();
  gdsr::Dataset d = gdsr::import_md(opt);
  bar.finish();
  gdsr::write_dataset(a.out, d);
  const auto& m = d.manifest;
  std::printf("imported %s: %d frames at %g fps, LR %d vertices, HR %d vertices, body %d vertices -> %s\n",
              m.garment.c_str(), m.frames, m.fps, m.lr_vertices, m.hr_vertices, m.body_vertices, a.out.c_str());
}

void run_check(const std::string& dir) {
  const gdsr::Dataset d = gdsr::load_dataset(dir);
  const auto& m = d.manifest;
  int covered = 0;
  for (int t : d.raster.tri) covered += t >= 0;
  std::printf("dataset %s: garment %s, %d layer(s), %d frames at %g fps (source %s)\n", dir.c_str(), m.garment.c_str(),
              m.layers, m.frames, m.fps, m.source_motion.c_str());
  std::printf("  LR: %d vertices, %d faces, %d UV vertices (particle distance %.4g m)\n", m.lr_vertices, m.lr_faces,
              m.lr_uv_vertices, m.lr_particle_distance);
  std::printf("  HR: %d vertices, %d faces, %d UV vertices (particle distance %.4g m)\n", m.hr_vertices, m.hr_faces,
              m.hr_uv_vertices, m.hr_particle_distance);
  std::printf("  body: %d vertices, %d faces\n", m.body_vertices, m.body_faces);
  std::printf("  UV raster: %d x %d, %.1f%% of pixels covered\n", d.raster.width, d.raster.height,
              100.0 * covered / std::max<size_t>(1, d.raster.tri.size()));
  std::printf("ok\n");
}

}  // namespace

void add_data_command(CLI::App& app) {
  CLI::App* data = app.add_subcommand("data", "make, preview, import and check paired LR/HR datasets");
  data->require_subcommand(1);

  auto imp = std::make_shared<ImportArgs>();
  CLI::App* im = data->add_subcommand("import-md", "import Marvelous Designer per-frame OBJ exports");
  im->add_option("--lr-dir", imp->opt.lr_dir, "folder of per-frame LR (30 mm) OBJs")->required();
  im->add_option("--hr-dir", imp->opt.hr_dir, "folder of per-frame HR (10 mm) OBJs")->required();
  im->add_option("--lr-uv", imp->opt.lr_uv, "flattened (UV) LR OBJ")->required();
  im->add_option("--hr-uv", imp->opt.hr_uv, "flattened (UV) HR OBJ")->required();
  im->add_option("--body-dir", imp->opt.body_dir, "folder of per-frame body OBJs (optional)");
  im->add_option("--garment", imp->opt.garment, "garment name")->capture_default_str();
  im->add_option("--fps", imp->opt.fps, "frames per second of the exports")->capture_default_str();
  im->add_option("--scale", imp->opt.scale, "file units to metres (0.001 for mm)")->capture_default_str();
  im->add_option("--out", imp->out, "dataset folder to write")->required();
  im->callback([imp]() { run_import(*imp); });

  auto check_dir = std::make_shared<std::string>();
  CLI::App* ch = data->add_subcommand("check", "load a dataset, validate it and print its counts");
  ch->add_option("--data", *check_dir, "dataset folder")->required();
  ch->callback([check_dir]() { run_check(*check_dir); });
}

// gdsr data make | preview | import-md | check
#include "train/commands.hpp"

#include "gdsr/body.hpp"
#include "gdsr/correspondence.hpp"
#include "gdsr/dataset.hpp"
#include "gdsr/md_import.hpp"
#include "gdsr/progress.hpp"
#include "gdsr/render.hpp"
#include "sim/cloth_solver.hpp"
#include "sim/garments.hpp"
#include "sim/sim_metrics.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <iostream>
#include <memory>
#include <stdexcept>

namespace {

struct MakeArgs {
  std::string garment = "skirt_short";
  std::string motion = "/usr/share/assimp/models/BVH/01_01.bvh";
  std::string out;
  double lr_pd = 0.03, hr_pd = 0.01;  // metres
  double seconds = 4.0;               // clip length after the rest blend
  double start = 0.0;                 // clip start, seconds
  double fps = 30;
  int substeps = -1;                  // <0: the solver's default
  int rest_blend_frames = 15;
  int raster = 1024;
};

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Process CPU time (all threads), seconds: wall time alone misleads on a loaded machine.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct SimRun {
  sim::Garment garment;
  std::vector<gdsr::Points3> frames;
  double seconds_per_frame = 0;      // wall clock
  double cpu_seconds_per_frame = 0;  // process CPU time
};

SimRun simulate_one(const MakeArgs& a, double pd, const char* label, const gdsr::BodySequence& body,
                    const sim::SimParams& params) {
  SimRun r;
  r.garment = sim::make_garment(a.garment, pd, body.rest_mesh());
  gdsr::ProgressBar bar(std::string("simulate ") + label + " (" + std::to_string(r.garment.mesh.V.rows()) + " vertices)");
  const double t0 = now_seconds(), c0 = cpu_seconds();
  r.frames = sim::simulate(r.garment, body, params, bar.callback());
  bar.finish();
  const double steps = static_cast<double>(std::max<size_t>(1, r.frames.size() + params.settle_frames));
  r.seconds_per_frame = (now_seconds() - t0) / steps;
  r.cpu_seconds_per_frame = (cpu_seconds() - c0) / steps;
  if (r.frames.size() != body.frames.size())
    throw std::runtime_error(std::string("data make: the ") + label + " simulation returned " +
                             std::to_string(r.frames.size()) + " frames for " + std::to_string(body.frames.size()) +
                             " body frames");
  return r;
}

// Means over the frames after the rest blend (all frames if the blend covers everything).
struct Summary {
  double hr_curv = 0, up_curv = 0, lr_curv = 0, hr_dih = 0, up_dih = 0;
  double lr_pen_max = 0, hr_pen_max = 0, lr_pen_mean = 0, hr_pen_mean = 0;
  sim::StrainEnergies lr_e, hr_e;
  double lr_ke_max = 0, hr_ke_max = 0;
};

Summary summarize(const gdsr::Dataset& d) {
  Summary s;
  const int T = static_cast<int>(d.lr_frames.size());
  const int first = d.manifest.rest_blend_frames < T ? d.manifest.rest_blend_frames : 0;
  const auto lr_m = sim::sequence_metrics(d.lr, d.lr_frames, d.body_faces, d.body_frames, d.manifest.fps);
  const auto hr_m = sim::sequence_metrics(d.hr, d.hr_frames, d.body_faces, d.body_frames, d.manifest.fps);
  const double n = T - first;
  for (int t = first; t < T; ++t) {
    const auto up = sim::wrinkle_measure(gdsr::upsample(d.corr, d.lr_frames[t]), d.hr.F);
    s.up_curv += up.mean_curvature / n;
    s.up_dih += up.mean_dihedral / n;
    s.hr_curv += hr_m[t].wrinkles.mean_curvature / n;
    s.hr_dih += hr_m[t].wrinkles.mean_dihedral / n;
    s.lr_curv += lr_m[t].wrinkles.mean_curvature / n;
    s.lr_pen_max = std::max(s.lr_pen_max, lr_m[t].penetration.max_depth);
    s.hr_pen_max = std::max(s.hr_pen_max, hr_m[t].penetration.max_depth);
    s.lr_pen_mean += lr_m[t].penetration.mean_depth / n;
    s.hr_pen_mean += hr_m[t].penetration.mean_depth / n;
    for (auto [e, m] : {std::make_pair(&s.lr_e, &lr_m[t]), std::make_pair(&s.hr_e, &hr_m[t])}) {
      e->E_u += m->strain.E_u / n;
      e->E_v += m->strain.E_v / n;
      e->E_uv += m->strain.E_uv / n;
    }
    s.lr_ke_max = std::max(s.lr_ke_max, lr_m[t].kinetic_energy);
    s.hr_ke_max = std::max(s.hr_ke_max, hr_m[t].kinetic_energy);
  }
  return s;
}

void run_make(const MakeArgs& a) {
  if (a.out.empty()) throw std::runtime_error("data make: --out is required");
  if (!(a.lr_pd > 0) || !(a.hr_pd > 0)) throw std::runtime_error("data make: particle distances must be positive");
  gdsr::BodyOptions bo;
  bo.fps = a.fps;
  bo.rest_blend_frames = a.rest_blend_frames;
  bo.start_seconds = a.start;
  bo.max_seconds = a.seconds;
  const double t_body = now_seconds();
  const gdsr::BodySequence body = gdsr::load_body_sequence(a.motion, bo);
  std::printf("body: %s, %d frames at %g fps (%d rest blend), %ld vertices, %.1f s\n", a.motion.c_str(),
              body.num_frames(), body.fps, body.rest_blend_frames, static_cast<long>(body.rest_V.rows()),
              now_seconds() - t_body);
  std::fflush(stdout);

  sim::SimParams params;
  if (a.substeps > 0) params.substeps = a.substeps;
  const SimRun lr = simulate_one(a, a.lr_pd, "LR", body, params);
  const SimRun hr = simulate_one(a, a.hr_pd, "HR", body, params);

  gdsr::Dataset d;
  d.lr = lr.garment.mesh;
  d.hr = hr.garment.mesh;
  d.lr_frames = lr.frames;
  d.hr_frames = hr.frames;
  d.body_frames = body.frames;
  d.body_faces = body.F;
  const double t_corr = now_seconds();
  d.corr = gdsr::compute_correspondence(d.lr, d.hr);
  d.raster = gdsr::rasterize_uv(d.hr.UV, d.hr.FUV, a.raster, a.raster);
  const double corr_seconds = now_seconds() - t_corr;

  gdsr::DatasetManifest& m = d.manifest;
  m.garment = a.garment;
  m.source_motion = a.motion;
  m.lr_particle_distance = a.lr_pd;
  m.hr_particle_distance = a.hr_pd;
  m.fps = body.fps;
  m.rest_blend_frames = body.rest_blend_frames;
  m.sim_params = {{"solver", "xpbd"},
                  {"substeps", params.substeps},
                  {"iterations", params.iterations},
                  {"thickness_m", params.thickness},
                  {"friction", params.friction},
                  {"density_kg_m2", params.density},
                  {"stretch_stiffness_n_m", params.stretch_stiffness},
                  {"bend_stiffness_n_m", params.bend_stiffness},
                  {"damping_1_s", params.damping},
                  {"settle_frames", params.settle_frames},
                  {"clip_start_s", a.start},
                  {"clip_seconds", a.seconds}};
  gdsr::update_manifest_counts(d);

  const Summary s = summarize(d);
  m.stats = {{"lr_seconds_per_frame", lr.seconds_per_frame},
             {"hr_seconds_per_frame", hr.seconds_per_frame},
             {"lr_cpu_seconds_per_frame", lr.cpu_seconds_per_frame},
             {"hr_cpu_seconds_per_frame", hr.cpu_seconds_per_frame},
             {"hr_mean_curvature_1_m", s.hr_curv},
             {"lr_upsampled_mean_curvature_1_m", s.up_curv},
             {"lr_mean_curvature_1_m", s.lr_curv},
             {"hr_mean_dihedral_rad", s.hr_dih},
             {"lr_upsampled_mean_dihedral_rad", s.up_dih},
             {"lr_max_penetration_m", s.lr_pen_max},
             {"hr_max_penetration_m", s.hr_pen_max},
             {"lr_energies", {{"E_u", s.lr_e.E_u}, {"E_v", s.lr_e.E_v}, {"E_uv", s.lr_e.E_uv}}},
             {"hr_energies", {{"E_u", s.hr_e.E_u}, {"E_v", s.hr_e.E_v}, {"E_uv", s.hr_e.E_uv}}},
             {"lr_max_kinetic_energy_j", s.lr_ke_max},
             {"hr_max_kinetic_energy_j", s.hr_ke_max}};
  gdsr::write_dataset(a.out, d);

  std::printf("dataset %s: %s on %s, %d frames at %g fps\n", a.out.c_str(), a.garment.c_str(), a.motion.c_str(),
              m.frames, m.fps);
  std::printf("  vertices: LR %d (pd %.3g m), HR %d (pd %.3g m), %.1fx; body %d\n", m.lr_vertices, a.lr_pd,
              m.hr_vertices, a.hr_pd, static_cast<double>(m.hr_vertices) / m.lr_vertices, m.body_vertices);
  std::printf("  seconds per frame (substeps %d): LR %.4f, HR %.4f wall; LR %.4f, HR %.4f CPU; correspondences + raster %.2f s\n",
              params.substeps, lr.seconds_per_frame, hr.seconds_per_frame, lr.cpu_seconds_per_frame,
              hr.cpu_seconds_per_frame, corr_seconds);
  std::printf("  wrinkles (mean |mean curvature|, 1/m): HR %.3f vs LR upsampled to HR %.3f (ratio %.2f); LR own %.3f\n",
              s.hr_curv, s.up_curv, s.up_curv > 0 ? s.hr_curv / s.up_curv : 0.0, s.lr_curv);
  std::printf("  mean dihedral on HR topology (rad): HR %.4f vs LR upsampled %.4f\n", s.hr_dih, s.up_dih);
  std::printf("  body penetration: max LR %.4f m, HR %.4f m; mean LR %.2e m, HR %.2e m\n", s.lr_pen_max, s.hr_pen_max,
              s.lr_pen_mean, s.hr_pen_mean);
  std::printf("  strain energies E_u / E_v / E_uv: LR %.4f / %.4f / %.4f, HR %.4f / %.4f / %.4f\n", s.lr_e.E_u, s.lr_e.E_v,
              s.lr_e.E_uv, s.hr_e.E_u, s.hr_e.E_v, s.hr_e.E_uv);
  std::printf("  max kinetic energy: LR %.4f J, HR %.4f J\n", s.lr_ke_max, s.hr_ke_max);
}

struct PreviewArgs {
  std::string data, out;
  int frame = -1;  // <0: last frame
  int size = 512;
  bool body = true;
};

void run_preview(const PreviewArgs& a) {
  const gdsr::Dataset d = gdsr::load_dataset(a.data);
  const int T = d.manifest.frames;
  if (T == 0) throw std::runtime_error("data preview: " + a.data + " has no frames");
  const int t = a.frame < 0 ? T - 1 : a.frame;
  if (t >= T)
    throw std::runtime_error("data preview: frame " + std::to_string(t) + " out of range (dataset has " +
                             std::to_string(T) + " frames)");
  const gdsr::TriMesh lr{d.lr_frames[t], d.lr.F}, hr{d.hr_frames[t], d.hr.F};
  // One camera for both images: framed on the HR garment (and the body around it).
  gdsr::Points3 all = hr.V;
  gdsr::RenderOptions opt;
  opt.width = opt.height = a.size;
  const Eigen::RowVector3d lo = all.colwise().minCoeff(), hi = all.colwise().maxCoeff();
  opt.center = (0.5 * (lo + hi)).transpose();
  opt.ortho_half_height = 0.5 * (hi - lo).maxCoeff() * 1.25;
  const cv::Vec3b body_c(200, 200, 200), lr_c(70, 120, 230), hr_c(60, 170, 90);  // BGR
  std::vector<gdsr::TriMesh> with_body;
  if (a.body && d.has_body()) with_body.push_back(gdsr::TriMesh{d.body_frames[t], d.body_faces});
  auto render = [&](const gdsr::TriMesh& g, const cv::Vec3b& c) {
    std::vector<gdsr::TriMesh> meshes = with_body;
    meshes.push_back(g);
    std::vector<cv::Vec3b> colours(with_body.size(), body_c);
    colours.push_back(c);
    return gdsr::render_meshes(meshes, colours, opt);
  };
  const cv::Mat img = gdsr::side_by_side(
      {render(lr, lr_c), render(hr, hr_c)},
      {"LR " + std::to_string(lr.num_vertices()) + " verts, frame " + std::to_string(t),
       "HR " + std::to_string(hr.num_vertices()) + " verts, frame " + std::to_string(t)});
  gdsr::write_png_atomic(a.out, img);
  std::printf("wrote %s (%d x %d): frame %d of %d, LR %d / HR %d vertices\n", a.out.c_str(), img.cols, img.rows, t, T,
              lr.num_vertices(), hr.num_vertices());
}

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

  auto mk = std::make_shared<MakeArgs>();
  CLI::App* make = data->add_subcommand("make", "simulate a garment at LR and HR on a motion and write a dataset");
  make->add_option("--garment", mk->garment, "garment name")->capture_default_str()->check(CLI::IsMember(sim::garment_names()));
  make->add_option("--motion", mk->motion, "motion file (BVH, FBX, glTF, Collada)")->capture_default_str();
  make->add_option("--out", mk->out, "dataset folder to write (atomically)")->required();
  make->add_option("--lr-pd", mk->lr_pd, "LR particle distance, metres")->capture_default_str();
  make->add_option("--hr-pd", mk->hr_pd, "HR particle distance, metres")->capture_default_str();
  make->add_option("--seconds", mk->seconds, "clip length in seconds (after the rest blend)")->capture_default_str();
  make->add_option("--start", mk->start, "clip start in seconds")->capture_default_str();
  make->add_option("--fps", mk->fps, "frames per second")->capture_default_str();
  make->add_option("--substeps", mk->substeps, "solver substeps per frame (default: the solver's)");
  make->add_option("--rest-blend", mk->rest_blend_frames, "frames blending from the rest pose")->capture_default_str();
  make->add_option("--raster", mk->raster, "UV raster size in pixels")->capture_default_str();
  make->callback([mk]() { run_make(*mk); });

  auto pv = std::make_shared<PreviewArgs>();
  CLI::App* prev = data->add_subcommand("preview", "render LR and HR of one frame side by side to a PNG");
  prev->add_option("--data", pv->data, "dataset folder")->required();
  prev->add_option("--frame", pv->frame, "frame index (default: the last)");
  prev->add_option("--out", pv->out, "PNG file to write")->required();
  prev->add_option("--size", pv->size, "pixels per image side")->capture_default_str();
  prev->add_flag("!--no-body", pv->body, "leave the body out");
  prev->callback([pv]() { run_preview(*pv); });

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
  im->add_option("--weld", imp->opt.weld, "merge 3-D vertices closer than this (metres) for unwelded exports");
  im->add_option("--out", imp->out, "dataset folder to write")->required();
  im->callback([imp]() { run_import(*imp); });

  auto check_dir = std::make_shared<std::string>();
  CLI::App* ch = data->add_subcommand("check", "load a dataset, validate it and print its counts");
  ch->add_option("--data", *check_dir, "dataset folder")->required();
  ch->callback([check_dir]() { run_check(*check_dir); });
}

// gdsr data make | preview | import-md | check
#include "gdsr/cli/commands.hpp"

#include "gdsr/error.hpp"

#include "gdsr/body/body.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/data/dataset.hpp"
#include "gdsr/data/md_import.hpp"
#include "gdsr/data/recipe.hpp"
#include "gdsr/data/validity.hpp"
#include "gdsr/geometry/self_intersections.hpp"
#include "gdsr/geometry/strain.hpp"
#include "gdsr/cli/progress_bar.hpp"
#include "gdsr/io/render.hpp"
#include "gdsr/sim/cloth_solver.hpp"
#include "gdsr/sim/garments.hpp"
#include "gdsr/sim/sim_metrics.hpp"
#include "train/run_log.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace {

// Self-intersections on every k-th frame by default (see `data check --help`).
constexpr int kDefaultIntersectionStride = 1;
// Sane bounds of `data make` (metres, frames per second, pixels).
constexpr double kMinParticleDistance = 0.002, kMaxParticleDistance = 0.5;
constexpr double kMaxFps = 240;
constexpr int kMinRaster = 8, kMaxRaster = 8192;

// CLI::Range lets NaN through (every comparison is false); this one does not.
CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) {
        double x = NAN;
        if (!CLI::detail::lexical_cast(s, x) || !(x >= lo && x <= hi))
          return "value " + s + " not in range [" + std::to_string(lo) + " - " + std::to_string(hi) + "]";
        return std::string();
      },
      "FLOAT in [" + std::to_string(lo) + " - " + std::to_string(hi) + "]");
}

struct MakeArgs {
  std::string garment = "skirt_short";
  std::string motion = "/usr/share/assimp/models/BVH/01_01.bvh";
  std::string out;
  double lr_pd = 0.03, hr_pd = 0.01;  // metres
  double seconds = 4.0;               // clip length after the rest blend
  double start = 0.0;                 // clip start, seconds
  double fps = 30;
  int substeps = -1;  // <0: the solver's default
  // Solver knobs (NaN / <0: the solver's default, sim::SimParams).
  int iterations = -1, stretch_passes = -1, settle_frames = -1, contact_every = -1, self_detect_every = -1,
      self_passes = -1;
  double friction = NAN, bend_stiffness = NAN, self_thickness = NAN, compression_ratio = NAN,
         compression_exponent = NAN, self_slack = NAN;
  double self_slack_per_pd = NAN, untangle_step = NAN, max_push_step = NAN, pinch_separation = NAN,
         dressed_radius = NAN;
  double contact_travel = NAN;
  double substep_travel = NAN;  // metres (sim::SimParams::substep_travel)
  int max_substeps = -1;
  double arm_clearance = 0.01;  // metres, gdsr::BodyOptions::arm_clearance (0: the motion as in the file)
  double min_shoulder_half_width = gdsr::BodyOptions{}.min_shoulder_half_width;  // metres (0: as in the file)
  double body_yield_gap = 0;  // metres, gdsr::BodyOptions::yield_gap (0: the skinned surface as it is)
  double pin_yield_rate = NAN;
  double track_rate = NAN;  // 1/s: the HR simulation follows the LR one at the LR scale (sim/cloth_tracking.hpp)
  bool self_collision = true;
  bool limbs_pass_through = true;
  bool limbs_pass_until_clear = true;
  bool self_redetect = true;
  bool self_tangle_retest = false;
  bool self_refuse_crossing_push = false;
  bool independent_hr = false;  // settle HR from its own placement, not from the settled LR garment
  bool skip_built = false;      // keep --out when it already holds this clip, built and valid
  int rest_blend_frames = 15;
  int raster = 1024;
  int intersection_stride = kDefaultIntersectionStride;
  std::string recipe;  // non-empty: build every clip of this recipe into out/<name>
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

// Where the HR settle started, as the manifest's sim_params.hr_start records it.
const char* hr_start_name(const MakeArgs& a) { return a.independent_hr ? "placement" : "settled_lr"; }

// The HR tracking rate in effect, 1/s (--track-rate, else the solver's default).
double effective_track_rate(const MakeArgs& a) {
  return std::isnan(a.track_rate) ? sim::SimParams().track_rate : a.track_rate;
}

// The largest move of a vertex per substep in effect, metres (--substep-travel, else the solver's).
double effective_substep_travel(const MakeArgs& a) {
  return std::isnan(a.substep_travel) ? sim::SimParams().substep_travel : a.substep_travel;
}

// The most substeps a frame may take in effect (--max-substeps, else the solver's).
int effective_max_substeps(const MakeArgs& a) {
  return a.max_substeps > 0 ? a.max_substeps : sim::SimParams().max_substeps;
}

// Substeps between body contact refreshes in effect (--contact-every, else the garment's).
int effective_contact_every(const MakeArgs& a) {
  return a.contact_every > 0 ? a.contact_every : sim::body_contact_every(a.garment, sim::SimParams().contact_every);
}

struct SimRun {
  sim::Garment garment;
  std::vector<gdsr::Points3> frames;
  double seconds_per_frame = 0;      // wall clock
  double cpu_seconds_per_frame = 0;  // process CPU time
  double substeps_per_frame = 0;     // mean, settle included (sim::SimParams::substep_travel)
};

SimRun simulate_one(sim::Garment garment, const char* label, const gdsr::BodySequence& body,
                    const sim::SimParams& params, const gdsr::Points3* start = nullptr,
                    const sim::Guide* guide = nullptr) {
  SimRun r;
  r.garment = std::move(garment);
  gdsr::ProgressBar bar(std::string("simulate ") + label + " (" + std::to_string(r.garment.mesh.V.rows()) +
                        " vertices)");
  const double t0 = now_seconds(), c0 = cpu_seconds();
  r.frames = sim::simulate(r.garment, body, params, bar.callback(), start, guide, &r.substeps_per_frame);
  bar.finish();
  const double steps = static_cast<double>(std::max<size_t>(1, r.frames.size() + params.settle_frames));
  r.seconds_per_frame = (now_seconds() - t0) / steps;
  r.cpu_seconds_per_frame = (cpu_seconds() - c0) / steps;
  if (r.frames.size() != body.frames.size())
    gdsr::fail("data make", std::string("the ") + label + " simulation returned " + std::to_string(r.frames.size()) +
                                " frames for " + std::to_string(body.frames.size()) + " body frames");
  return r;
}

// Largest kinetic energy over the clip (joules), from consecutive frames.
double max_kinetic_energy(const gdsr::GarmentMesh& g, const std::vector<gdsr::Points3>& frames, double fps) {
  double e = 0;
  for (size_t t = 1; t < frames.size(); ++t)
    e = std::max(e, sim::kinetic_energy(g, frames[t - 1], frames[t], 1.0 / fps));
  return e;
}

// The frames as the dataset stores them (float32), so that `data make` measures exactly what
// `data check` later loads.
void round_to_float(std::vector<gdsr::Points3>& frames) {
  for (auto& X : frames) X = X.cast<float>().cast<double>();
}

gdsr::ValidityFigures measure(const gdsr::Dataset& d, const gdsr::ValidityOptions& opt, double& seconds) {
  gdsr::ProgressBar bar("validity figures");
  const double t0 = now_seconds();
  const gdsr::ValidityFigures v = gdsr::measure_validity(d, opt, bar.callback());
  bar.finish();
  seconds = now_seconds() - t0;
  return v;
}

bool built_and_valid(const std::string& dir, const MakeArgs& a, std::string& why);

void run_make(const MakeArgs& a) {
  if (a.skip_built) {
    std::string why;
    if (built_and_valid(a.out, a, why)) {
      std::printf("kept %s: already built from this clip by this solver revision\n", a.out.c_str());
      return;
    }
    std::printf("building %s (%s)\n", a.out.c_str(), why.c_str());
  }
  // Everything that can be refused is refused here, before minutes of simulation.
  gdsr::check_dataset_out(a.out);
  if (!(a.hr_pd <= a.lr_pd))
    gdsr::fail("--hr-pd", "the HR particle distance " + std::to_string(a.hr_pd) +
                              " m is coarser than the LR one (--lr-pd " + std::to_string(a.lr_pd) + " m)");
  const int least = a.substeps > 0 ? a.substeps : sim::SimParams().substeps;
  if (effective_substep_travel(a) > 0 && effective_max_substeps(a) < least)
    gdsr::fail("--max-substeps",
               std::to_string(effective_max_substeps(a)) + " is fewer than --substeps " + std::to_string(least));
  gdsr::BodyOptions bo;
  bo.fps = a.fps;
  bo.rest_blend_frames = a.rest_blend_frames;
  bo.start_seconds = a.start;
  bo.max_seconds = a.seconds;
  bo.rest_arm_drop_degrees = sim::rest_arm_drop_degrees(a.garment);
  bo.arm_clearance = a.arm_clearance;
  bo.min_shoulder_half_width = a.min_shoulder_half_width;
  bo.yield_gap = a.body_yield_gap;
  const double t_body = now_seconds();
  const gdsr::BodySequence body = gdsr::load_body_sequence(a.motion, bo);
  std::printf("body: %s, %d frames at %g fps (%d rest blend), %ld vertices, %.1f s\n", a.motion.c_str(),
              body.num_frames(), body.fps, body.rest_blend_frames, static_cast<long>(body.rest_V.rows()),
              now_seconds() - t_body);
  if (bo.rest_arm_drop_degrees >= 0)
    std::printf("body: rest pose with the upper arms %g degrees below level (the %s is cut for it)\n",
                bo.rest_arm_drop_degrees, a.garment.c_str());
  if (body.shoulders_widened)
    std::printf(
        "body: shoulder joints %.3f m from the middle in the file, moved out to %.3f m "
        "(--min-shoulder-half-width)\n",
        body.captured_shoulder_half_width, bo.min_shoulder_half_width);
  if (body.arm_turns.turned_frames() > 0)
    std::printf(
        "body: an arm came within %g mm of the trunk or legs in %d frames; turned out at the shoulder by "
        "up to %.1f degrees (%d frames still inside after the largest turn)\n",
        1e3 * bo.arm_clearance, body.arm_turns.turned_frames(), body.arm_turns.max_degrees(),
        body.arm_turns.still_inside_frames);
  if (body.yields.yielded_frames() > 0)
    std::printf(
        "body: one part passed into another in %d frames; both gave way, by up to %.1f mm (%d frames still "
        "overlapping after the last pass)\n",
        body.yields.yielded_frames(), 1e3 * body.yields.max_move_overall(), body.yields.buried_left_frames);
  if (!body.torso_found)
    std::fprintf(stderr,
                 "warning: %s: no hips and shoulders found among the skeleton's joint names; the body is a "
                 "column of capsules without shoulders, neck or waist (gdsr/body/skeleton_body.cpp: classify)\n",
                 a.motion.c_str());
  std::fflush(stdout);

  sim::SimParams params;
  if (a.substeps > 0) params.substeps = a.substeps;
  params.substep_travel = effective_substep_travel(a);
  params.max_substeps = effective_max_substeps(a);
  if (a.iterations > 0) params.iterations = a.iterations;
  if (a.stretch_passes > 0) params.stretch_passes = a.stretch_passes;
  if (a.settle_frames >= 0) params.settle_frames = a.settle_frames;
  params.contact_every = effective_contact_every(a);
  if (!std::isnan(a.contact_travel)) params.contact_travel = a.contact_travel;
  if (!std::isnan(a.pin_yield_rate)) params.pin_yield_rate = a.pin_yield_rate;
  if (!std::isnan(a.friction)) params.friction = a.friction;
  if (!std::isnan(a.bend_stiffness)) params.bend_stiffness = a.bend_stiffness;
  if (!std::isnan(a.self_thickness)) params.self_thickness = a.self_thickness;
  if (!std::isnan(a.self_slack)) params.self_slack = a.self_slack;
  if (!std::isnan(a.self_slack_per_pd)) params.self_slack_per_pd = a.self_slack_per_pd;
  if (a.self_detect_every > 0) params.self_detect_every = a.self_detect_every;
  if (a.self_passes > 0) params.self_passes = a.self_passes;
  if (!std::isnan(a.compression_ratio)) params.compression_ratio = a.compression_ratio;
  if (!std::isnan(a.compression_exponent)) params.compression_pd_exponent = a.compression_exponent;
  if (!std::isnan(a.untangle_step)) params.untangle_step = a.untangle_step;
  if (!std::isnan(a.max_push_step)) params.max_push_step = a.max_push_step;
  if (!std::isnan(a.pinch_separation)) params.pinch_separation = a.pinch_separation;
  if (!std::isnan(a.dressed_radius)) params.dressed_radius = a.dressed_radius;
  params.track_rate = effective_track_rate(a);
  params.self_collision = a.self_collision;
  params.limbs_pass_through = a.limbs_pass_through;
  params.limbs_pass_until_clear = a.limbs_pass_until_clear;
  params.self_redetect = a.self_redetect;
  params.self_tangle_retest = a.self_tangle_retest;
  params.self_refuse_crossing_push = a.self_refuse_crossing_push;
  sim::Garment lr_garment = sim::make_garment(a.garment, a.lr_pd, body.rest_mesh());
  sim::Garment hr_garment = sim::make_garment(a.garment, a.hr_pd, body.rest_mesh());
  gdsr::Dataset d;
  d.lr = lr_garment.mesh;
  d.hr = hr_garment.mesh;
  const double t_corr = now_seconds();
  d.corr = gdsr::compute_correspondence(d.lr, d.hr);
  d.raster = gdsr::rasterize_uv(d.hr.UV, d.hr.FUV, a.raster, a.raster);
  const double corr_seconds = now_seconds() - t_corr;

  const SimRun lr = simulate_one(std::move(lr_garment), "LR", body, params);
  // Both resolutions start the clip in one drape (see sim::simulate_frames).
  const gdsr::Points3 hr_start = a.independent_hr ? gdsr::Points3() : gdsr::upsample(d.corr, lr.frames.front());
  const sim::GuideTracker tracker(d.corr);
  const sim::Guide guide{tracker, lr.frames};
  const SimRun hr = simulate_one(std::move(hr_garment), "HR", body, params, a.independent_hr ? nullptr : &hr_start,
                                 params.track_rate > 0 ? &guide : nullptr);
  d.lr_frames = lr.frames;
  d.hr_frames = hr.frames;
  d.body_frames = body.frames;
  d.body_faces = body.F;

  gdsr::DatasetManifest& m = d.manifest;
  m.garment = a.garment;
  m.source_motion = a.motion;
  m.lr_particle_distance = a.lr_pd;
  m.hr_particle_distance = a.hr_pd;
  m.fps = body.fps;
  m.rest_blend_frames = body.rest_blend_frames;
  m.sim_params = {{"solver", "xpbd"},
                  {"solver_revision", sim::kSolverRevision},
                  {"substeps", params.substeps},
                  {"substep_travel_m", params.substep_travel},
                  {"max_substeps", params.max_substeps},
                  {"iterations", params.iterations},
                  {"stretch_passes", params.stretch_passes},
                  {"thickness_m", params.thickness},
                  {"layer_gap_m", params.layer_gap},
                  {"friction", params.friction},
                  {"density_kg_m2", params.density},
                  {"stretch_stiffness_n_m", params.stretch_stiffness},
                  {"bend_stiffness_n_m", params.bend_stiffness},
                  {"damping_1_s", params.damping},
                  {"settle_frames", params.settle_frames},
                  {"contact_every", params.contact_every},
                  {"contact_travel", params.contact_travel},
                  {"pin_yield_rate_1_s", params.pin_yield_rate},
                  {"settle_damping_1_s", params.settle_damping},
                  {"settle_rest_blend", params.settle_rest_blend},
                  {"hr_start", hr_start_name(a)},
                  {"rest_arm_drop_degrees", bo.rest_arm_drop_degrees},
                  {"arm_clearance_m", bo.arm_clearance},
                  {"min_shoulder_half_width_m", bo.min_shoulder_half_width},
                  {"captured_shoulder_half_width_m", body.captured_shoulder_half_width},
                  {"shoulders_widened", body.shoulders_widened},
                  {"arm_turned_frames", body.arm_turns.turned_frames()},
                  {"arm_turn_max_degrees", body.arm_turns.max_degrees()},
                  {"body_yield_gap_m", bo.yield_gap},
                  {"body_yielded_frames", body.yields.yielded_frames()},
                  {"body_yield_max_mm", 1e3 * body.yields.max_move_overall()},
                  {"arm_still_inside_frames", body.arm_turns.still_inside_frames},
                  {"self_collision", params.self_collision},
                  {"limbs_pass_through", params.limbs_pass_through},
                  {"limbs_pass_until_clear", params.limbs_pass_until_clear},
                  {"max_push_step_m", params.max_push_step},
                  {"pinch_separation_m", params.pinch_separation},
                  {"dressed_radius_m", params.dressed_radius},
                  {"self_thickness_m", params.self_thickness},
                  {"self_thickness_per_pd", params.self_thickness_per_pd},
                  {"self_slack_m", params.self_slack},
                  {"self_slack_per_pd", params.self_slack_per_pd},
                  {"self_detect_every", params.self_detect_every},
                  {"self_passes", params.self_passes},
                  {"self_crossed_push", params.self_crossed_push},
                  {"self_redetect", params.self_redetect},
                  {"self_tangle_retest", params.self_tangle_retest},
                  {"self_refuse_crossing_push", params.self_refuse_crossing_push},
                  {"untangle_step", params.untangle_step},
                  {"hr_track_rate_1_s", params.track_rate},
                  {"compression_ratio", params.compression_ratio},
                  {"compression_pd_ref_m", params.compression_pd_ref},
                  {"compression_pd_exponent", params.compression_pd_exponent},
                  {"clip_start_s", a.start},
                  {"clip_seconds", a.seconds}};
  gdsr::update_manifest_counts(d);

  round_to_float(d.lr_frames);
  round_to_float(d.hr_frames);
  round_to_float(d.body_frames);
  d.lr = gdsr::as_written_obj(d.lr);
  d.hr = gdsr::as_written_obj(d.hr);
  gdsr::ValidityOptions vo;
  vo.intersection_stride = a.intersection_stride;
  double validity_seconds = 0;
  const gdsr::ValidityFigures v = measure(d, vo, validity_seconds);
  m.validity = gdsr::validity_to_json(v);
  const double lr_ke = max_kinetic_energy(d.lr, d.lr_frames, m.fps),
               hr_ke = max_kinetic_energy(d.hr, d.hr_frames, m.fps);
  m.stats = {{"lr_seconds_per_frame", lr.seconds_per_frame},
             {"hr_seconds_per_frame", hr.seconds_per_frame},
             {"lr_cpu_seconds_per_frame", lr.cpu_seconds_per_frame},
             {"hr_cpu_seconds_per_frame", hr.cpu_seconds_per_frame},
             {"lr_substeps_per_frame", lr.substeps_per_frame},
             {"hr_substeps_per_frame", hr.substeps_per_frame},
             {"lr_max_kinetic_energy_j", lr_ke},
             {"hr_max_kinetic_energy_j", hr_ke}};
  gdsr::write_dataset(a.out, d);

  std::printf("dataset %s: %s on %s, %d frames at %g fps\n", a.out.c_str(), a.garment.c_str(), a.motion.c_str(),
              m.frames, m.fps);
  std::printf("  vertices: LR %d (pd %.3g m), HR %d (pd %.3g m), %.1fx; body %d\n", m.lr_vertices, a.lr_pd,
              m.hr_vertices, a.hr_pd, static_cast<double>(m.hr_vertices) / m.lr_vertices, m.body_vertices);
  std::printf(
      "  seconds per frame (substeps per frame LR %.1f, HR %.1f): LR %.4f, HR %.4f wall; LR %.4f, HR %.4f CPU; "
      "correspondences + raster %.2f s\n",
      lr.substeps_per_frame, hr.substeps_per_frame, lr.seconds_per_frame, hr.seconds_per_frame,
      lr.cpu_seconds_per_frame, hr.cpu_seconds_per_frame, corr_seconds);
  std::printf("  max kinetic energy: LR %.4f J, HR %.4f J\n", lr_ke, hr_ke);
  std::printf("%s", gdsr::validity_table(v).c_str());
  std::printf("  (validity figures: %.1f s)\n", validity_seconds);
}

// True when dir holds a dataset made from exactly this clip and recipe that loads cleanly
// (every array's checksum verified); why not in `why` otherwise.
bool built_and_valid(const std::string& dir, const MakeArgs& a, std::string& why) {
  namespace fs = std::filesystem;
  if (!fs::exists(fs::path(dir) / "manifest.json")) {
    why = "not built";
    return false;
  }
  try {
    const gdsr::DatasetManifest m = gdsr::read_manifest((fs::path(dir) / "manifest.json").string());
    const auto& sp = m.sim_params;
    auto same = [](double x, double y) { return std::abs(x - y) <= 1e-9 * std::max(1.0, std::abs(y)); };
    if (m.garment != a.garment || m.source_motion != a.motion || !same(m.lr_particle_distance, a.lr_pd) ||
        !same(m.hr_particle_distance, a.hr_pd) || !same(m.fps, a.fps) || m.rest_blend_frames != a.rest_blend_frames ||
        !sp.contains("clip_start_s") || !same(sp["clip_start_s"].get<double>(), a.start) ||
        !sp.contains("clip_seconds") || !same(sp["clip_seconds"].get<double>(), a.seconds) || m.validity.empty()) {
      why = "built from other settings";
      return false;
    }
    if (!sp.contains("solver_revision") || sp["solver_revision"] != sim::kSolverRevision) {
      why = "built by an older solver";
      return false;
    }
    if (!same(sp.value("arm_clearance_m", 0.0), a.arm_clearance)) {
      why = "built with another arm clearance";
      return false;
    }
    if (!same(sp.value("body_yield_gap_m", 0.0), a.body_yield_gap)) {
      why = "built with another body yield gap";
      return false;
    }
    // Another limit changes nothing when the file's shoulders are wider than both.
    const double built_limit = sp.value("min_shoulder_half_width_m", 0.0);
    if (!same(built_limit, a.min_shoulder_half_width) &&
        !(sp.value("captured_shoulder_half_width_m", 0.0) >= std::max(built_limit, a.min_shoulder_half_width))) {
      why = "built with another shoulder width limit";
      return false;
    }
    if (!same(sp.value("substep_travel_m", 0.0), effective_substep_travel(a)) ||
        (effective_substep_travel(a) > 0 && sp.value("max_substeps", 0) != effective_max_substeps(a))) {
      why = "built with other adaptive substeps";
      return false;
    }
    if (sp.value("contact_every", 0) != effective_contact_every(a)) {
      why = "built with another body contact refresh";
      return false;
    }
    if (sp.value("self_tangle_retest", false) != a.self_tangle_retest) {
      why = "built with another tangle test cue";
      return false;
    }
    if (sp.value("self_refuse_crossing_push", false) != a.self_refuse_crossing_push) {
      why = "built with another rule for pushes back across";
      return false;
    }
    if (sp.value("hr_start", "") != hr_start_name(a)) {
      why = "built with another HR start";
      return false;
    }
    if (!same(sp.value("hr_track_rate_1_s", 0.0), effective_track_rate(a))) {
      why = "built with another HR tracking rate";
      return false;
    }
    gdsr::load_dataset(dir);
  } catch (const std::exception& e) {
    why = std::string("invalid (") + e.what() + ")";
    return false;
  }
  return true;
}

void run_recipe(const MakeArgs& a) {
  namespace fs = std::filesystem;
  const gdsr::Recipe r = gdsr::load_recipe(a.recipe, sim::garment_names());
  if (fs::exists(fs::path(a.out) / "manifest.json") || (fs::exists(a.out) && !fs::is_directory(a.out)))
    gdsr::fail("--out", a.out + " is a dataset or a file; a recipe builds a folder of datasets");
  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec) gdsr::fail("--out", "cannot create " + a.out + ": " + ec.message());
  nlohmann::json splits = {{"recipe", fs::absolute(a.recipe).string()},
                           {"train", nlohmann::json::array()},
                           {"heldout", nlohmann::json::array()}};
  const int n = static_cast<int>(r.clips.size());
  int built = 0, skipped = 0;
  for (int k = 0; k < n; ++k) {
    const gdsr::RecipeClip& c = r.clips[k];
    MakeArgs one = a;
    one.recipe.clear();
    one.skip_built = false;  // checked just below
    one.garment = c.garment;
    one.motion = c.motion;
    one.start = c.start;
    one.seconds = c.seconds;
    one.lr_pd = r.lr_pd;
    one.hr_pd = r.hr_pd;
    one.fps = r.fps;
    one.rest_blend_frames = r.rest_blend;
    if (!std::isnan(r.hr_track_rate)) one.track_rate = r.hr_track_rate;  // else --track-rate or the solver's
    one.out = (fs::path(a.out) / c.name).string();
    std::string why;
    if (built_and_valid(one.out, one, why)) {
      std::printf("[%d/%d] %s: built and valid, skipped\n", k + 1, n, c.name.c_str());
      ++skipped;
    } else {
      std::printf("[%d/%d] %s (%s): %s on %s from %g s for %g s\n", k + 1, n, c.name.c_str(), why.c_str(),
                  c.garment.c_str(), c.motion.c_str(), c.start, c.seconds);
      std::fflush(stdout);
      run_make(one);
      ++built;
    }
    std::fflush(stdout);
    splits[c.heldout ? "heldout" : "train"].push_back(c.name);
  }
  gdsr::write_text_atomic((fs::path(a.out) / "splits.json").string(), splits.dump(2) + "\n");
  std::printf("recipe %s: %d built, %d already built; %zu train and %zu held-out datasets in %s (splits.json)\n",
              a.recipe.c_str(), built, skipped, splits["train"].size(), splits["heldout"].size(), a.out.c_str());
  std::string cmd = "gdsr train";
  for (const auto& t : splits["train"]) cmd += " --data " + (fs::path(a.out) / t.get<std::string>()).string();
  for (const auto& t : splits["heldout"]) cmd += " --val-data " + (fs::path(a.out) / t.get<std::string>()).string();
  std::printf("train on it: %s --out RUN\n", cmd.c_str());
}

// --pinch-gap in mm (gdsr::ValidityOptions::pinch_gap), for `data check` and `data preview`.
double default_pinch_gap_mm() { return 1e3 * gdsr::ValidityOptions{}.pinch_gap; }
void add_pinch_gap_option(CLI::App* cmd, double& mm, const std::string& lead) {
  cmd->add_option("--pinch-gap", mm,
                  "mm: " + lead +
                      "cloth in a crease of one body part closed to less than this is pinched (0: off, as manifests "
                      "measured before the crease rule)")
      ->capture_default_str()
      ->check(finite_range(0.0, 1000.0));
}

struct PreviewArgs {
  std::string data, out;
  int frame = -1;  // <0: last frame
  int size = 512;
  bool body = true;
  bool intersections = false;  // paint the faces of intersecting pairs red
  bool penetration = false;    // paint the faces inside the body (outside pinches magenta, pinched cyan)
  bool strain = false;         // paint faces by their most strained fibre (shorter blue, longer yellow / red)
  double pinch_gap_mm = default_pinch_gap_mm();  // the crease rule of `data check`
  std::string view = "front";  // where the camera is, relative to the body's first pose (Y-up, facing +z)
  int layer = -1;              // >= 0: draw only this cloth layer's faces (0: innermost)
};

// Preview cameras: direction and image up, the camera on the body's side named (the body's
// left is +x, its front +z; from the top, its front is at the bottom of the image).
struct View {
  const char* name;
  gdsr::Vec3 dir, up;
};
const View kViews[] = {{"front", {0, 0, -1}, {0, 1, 0}},
                       {"back", {0, 0, 1}, {0, 1, 0}},
                       {"left", {-1, 0, 0}, {0, 1, 0}},
                       {"right", {1, 0, 0}, {0, 1, 0}},
                       {"top", {0, -1, 0}, {0, 0, -1}}};

// --view was checked against kViews by the command line.
void set_view(const std::string& view, gdsr::RenderOptions& opt) {
  for (const View& v : kViews)
    if (view == v.name) {
      opt.view_dir = v.dir;
      opt.up = v.up;
    }
}

// Labels of the garment's faces for --intersections, --penetration and --strain, one colour each.
enum FaceMark {
  kPlain,
  kPinched,
  kInBody,
  kIntersecting,
  kCompressedMuch,  // --strain: a fibre more than kStrainMuch shorter than in the pattern
  kCompressed,      // more than kStrainSome shorter
  kStretched,       // more than kStrainSome longer (and none shorter by more)
  kStretchedMuch,
  kMarks
};
constexpr double kStrainSome = 0.02, kStrainMuch = 0.05;  // of the fibre's pattern length

// Marks the faces left plain by their fibre strained most (|w| - 1 of the u or the v fibre,
// gdsr::fibre_stretch); returns the faces marked compressed and stretched.
std::array<int, 2> mark_strain(const gdsr::GarmentMesh& g, const gdsr::Points3& X, std::vector<int>& mark) {
  const std::vector<gdsr::Vec2> w = gdsr::fibre_stretch(g, X);
  std::array<int, 2> n{0, 0};
  for (size_t f = 0; f < w.size(); ++f) {
    if (mark[f] != kPlain || !w[f].allFinite()) continue;
    const double du = w[f].x() - 1, dv = w[f].y() - 1;
    const double e = std::abs(du) >= std::abs(dv) ? du : dv;
    const int m = e < -kStrainMuch   ? kCompressedMuch
                  : e < -kStrainSome ? kCompressed
                  : e > kStrainMuch  ? kStretchedMuch
                  : e > kStrainSome  ? kStretched
                                     : kPlain;
    mark[f] = m;
    n[0] += m == kCompressedMuch || m == kCompressed;
    n[1] += m == kStretchedMuch || m == kStretched;
  }
  return n;
}

// Marks the faces in an intersecting pair (CGAL); returns how many.
int mark_intersections(const gdsr::TriMesh& g, std::vector<int>& mark) {
  const gdsr::SelfIntersections si = gdsr::self_intersections(g.V, g.F, /*list_pairs=*/true);
  int marked = 0;
  for (const auto& [f, h] : si.list)
    for (int k : {f, h}) marked += std::exchange(mark[k], kIntersecting) != kIntersecting;
  return marked;
}

// Marks the faces with a corner deeper than opt.penetration_limit in the body in frame t:
// kInBody if one such corner is outside pinches, else kPinched (gdsr::body_depths, the rule of
// `data check`). Faces already marked keep their mark.
struct InBody {
  int faces = 0, pinched = 0;  // faces marked kInBody / kPinched (whatever mark they kept)
  double deepest = 0;          // metres, deepest corner outside pinches (0: none past the limit)
};
InBody mark_penetration(const gdsr::Dataset& d, int t, const gdsr::TriMesh& g, double pinch_gap,
                        std::vector<int>& mark) {
  gdsr::ValidityOptions opt;
  opt.pinch_gap = pinch_gap;
  const gdsr::BodyDepths bd = gdsr::body_depths(d, t, g.V, opt);
  InBody r;
  for (int f = 0; f < g.F.rows(); ++f) {
    int m = kPlain;
    for (int k = 0; k < 3; ++k) {
      const int v = g.F(f, k);
      if (!(bd.depth[v] > opt.penetration_limit)) continue;
      m = std::max(m, bd.pinched[v] ? int{kPinched} : int{kInBody});
      if (!bd.pinched[v]) r.deepest = std::max(r.deepest, bd.depth[v]);
    }
    r.faces += m == kInBody;
    r.pinched += m == kPinched;
    if (mark[f] == kPlain) mark[f] = m;
  }
  return r;
}

// The garment as one mesh per mark (empty meshes left out: the renderer refuses them).
void add_marked(const gdsr::TriMesh& g, const std::vector<int>& mark, const std::array<cv::Vec3b, kMarks>& colour,
                std::vector<gdsr::TriMesh>& meshes, std::vector<cv::Vec3b>& colours) {
  for (int m = 0; m < kMarks; ++m) {
    const int n = static_cast<int>(std::count(mark.begin(), mark.end(), m));
    if (n == 0) continue;
    gdsr::TriMesh part{g.V, gdsr::Faces(n, 3)};
    for (int f = 0, i = 0; f < g.F.rows(); ++f)
      if (mark[f] == m) part.F.row(i++) = g.F.row(f);
    meshes.push_back(std::move(part));
    colours.push_back(colour[m]);
  }
}

// X-ray: the faces marked kPinched, kInBody or kIntersecting drawn over img (rendered with opt)
// at 65% opacity, so that the body or the cloth that hides them does not (a knot between the
// layers of a tiered skirt lies under its outer tier).
void draw_through(const gdsr::TriMesh& g, std::vector<int> mark, const std::array<cv::Vec3b, kMarks>& colour,
                  const gdsr::RenderOptions& opt, cv::Mat& img) {
  for (int& m : mark)
    if (m == kPlain || m >= kCompressedMuch) m = -1;  // strain is painted on the surface only
  std::vector<gdsr::TriMesh> parts;
  std::vector<cv::Vec3b> colours;
  add_marked(g, mark, colour, parts, colours);
  if (parts.empty()) return;
  const cv::Mat over = gdsr::render_meshes(parts, colours, opt);
  const cv::Scalar bg(opt.background[0], opt.background[1], opt.background[2]);
  cv::Mat empty, blend;
  cv::inRange(over, bg, bg, empty);
  cv::addWeighted(img, 0.35, over, 0.65, 0, blend);
  blend.copyTo(img, ~empty);
}

// The faces of g (and their marks) on cloth layer `layer` (gdsr::faces_by_layer: the layer of
// a face's first corner; `layers` per vertex, empty: one layer, 0).
void keep_layer(int layer, const std::vector<int>& layers, gdsr::TriMesh& g, std::vector<int>& mark) {
  const std::vector<std::vector<int>> by_layer = gdsr::faces_by_layer(layers, g.F);
  const std::vector<int> none;
  const std::vector<int>& kept = layer < static_cast<int>(by_layer.size()) ? by_layer[layer] : none;
  gdsr::Faces F(static_cast<Eigen::Index>(kept.size()), 3);
  std::vector<int> m(kept.size());
  for (size_t i = 0; i < kept.size(); ++i) {
    F.row(static_cast<Eigen::Index>(i)) = g.F.row(kept[i]);
    m[i] = mark[kept[i]];
  }
  g.F = std::move(F);
  mark = std::move(m);
}

void run_preview(const PreviewArgs& a) {
  const gdsr::Dataset d = gdsr::load_dataset(a.data);
  const int T = d.manifest.frames;
  if (T == 0) gdsr::fail("data preview", a.data + " has no frames");
  const int t = a.frame < 0 ? T - 1 : a.frame;
  if (t >= T)
    gdsr::fail("--frame", std::to_string(t) + " out of range (" + a.data + " has " + std::to_string(T) + " frames)");
  const int layers = std::min(d.lr.num_layers(), d.hr.num_layers());
  if (a.layer >= layers)
    gdsr::fail("--layer",
               std::to_string(a.layer) + " out of range (" + a.data + " has " +
                   (layers == 1 ? "one layer: 0)"
                                : std::to_string(layers) + " layers: 0-" + std::to_string(layers - 1) + ")"));
  const gdsr::TriMesh lr{d.lr_frames[t], d.lr.F}, hr{d.hr_frames[t], d.hr.F};
  // One camera for both images: framed on the HR garment (and the body around it).
  gdsr::Points3 all = hr.V;
  gdsr::RenderOptions opt;
  opt.width = opt.height = a.size;
  set_view(a.view, opt);
  const Eigen::RowVector3d lo = all.colwise().minCoeff(), hi = all.colwise().maxCoeff();
  opt.center = (0.5 * (lo + hi)).transpose();
  opt.ortho_half_height = 0.5 * (hi - lo).maxCoeff() * 1.25;
  const cv::Vec3b body_c(200, 200, 200), lr_c(70, 120, 230), hr_c(60, 170, 90);  // BGR
  std::vector<gdsr::TriMesh> with_body;
  if (a.body && d.has_body()) with_body.push_back(gdsr::TriMesh{d.body_frames[t], d.body_faces});
  // --intersections: the body's faces where one part passes into another (the rule of `data check`).
  gdsr::TriMesh body_crossing;
  if (a.intersections && !with_body.empty()) {
    const auto pairs = gdsr::body_crossing_pairs(d.body_frames[t], d.body_faces, d.body_frames[0],
                                                 gdsr::ValidityOptions{}.pinch_separation);
    std::vector<int> faces;
    for (const auto& [f, g] : pairs) faces.insert(faces.end(), {f, g});
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    body_crossing.V = d.body_frames[t];
    body_crossing.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
    for (size_t i = 0; i < faces.size(); ++i)
      body_crossing.F.row(static_cast<Eigen::Index>(i)) = d.body_faces.row(faces[i]);
    std::printf("body: %zu faces where one part passes into another (CGAL, parts %g m apart in the first frame)\n",
                faces.size(), gdsr::ValidityOptions{}.pinch_separation);
  }
  if (a.penetration && !d.has_body()) gdsr::fail("--penetration", a.data + " has no body");
  const std::string view_note = a.view == "front" ? "" : ", " + a.view;
  std::string lr_note = view_note, hr_note = view_note;
  auto render = [&](const char* name, const gdsr::GarmentMesh& garment, const gdsr::TriMesh& whole,
                    const std::vector<int>& layer_of, const cv::Vec3b& c, std::string& note) {
    std::vector<gdsr::TriMesh> meshes = with_body;
    std::vector<cv::Vec3b> colours(with_body.size(), body_c);
    std::vector<int> mark(whole.F.rows(), kPlain);
    // Marked on the whole garment (a layer's faces crossing another layer's count), then cut to --layer.
    const int crossing = a.intersections ? mark_intersections(whole, mark) : 0;
    std::vector<int> strained(whole.F.rows(), kPlain);
    if (a.strain) {
      const std::array<int, 2> n = mark_strain(garment, whole.V, strained);
      note += ", " + std::to_string(n[0]) + " compressed / " + std::to_string(n[1]) + " stretched";
      std::printf("%s: %d faces with a fibre more than %g%% shorter than in the pattern, %d more than %g%% longer\n",
                  name, n[0], 100 * kStrainSome, n[1], 100 * kStrainSome);
    }
    gdsr::TriMesh g = whole;
    if (a.layer >= 0) {
      gdsr::TriMesh cut = whole;
      keep_layer(a.layer, layer_of, cut, strained);
      keep_layer(a.layer, layer_of, g, mark);
    }
    if (a.intersections) {
      const long shown = std::count(mark.begin(), mark.end(), int{kIntersecting});
      note += a.layer >= 0 ? ", " + std::to_string(shown) + "/" + std::to_string(crossing) + " intersect"
                           : ", " + std::to_string(crossing) + " faces intersect";
      std::printf("%s: %d faces in intersecting pairs", name, crossing);
      if (a.layer >= 0) std::printf(", %ld of them on layer %d", shown, a.layer);
      std::printf("\n");
    }
    if (a.penetration) {
      const InBody in = mark_penetration(d, t, g, 1e-3 * a.pinch_gap_mm, mark);
      note += ", " + std::to_string(in.faces) + " in body (" + std::to_string(in.pinched) + " pinched)";
      std::printf("%s: %d faces%s with a corner > %g mm in the body outside pinches (deepest %.1f mm), %d pinched\n",
                  name, in.faces, a.layer >= 0 ? (" on layer " + std::to_string(a.layer)).c_str() : "",
                  1000 * gdsr::ValidityOptions{}.penetration_limit, 1000 * in.deepest, in.pinched);
    }
    // Strain under the other marks: they win where a face has both.
    for (size_t f = 0; f < mark.size(); ++f)
      if (mark[f] == kPlain) mark[f] = strained[f];
    // BGR: cloth, pinched cyan, in the body magenta, intersecting red; strain: compressed dark /
    // light blue, stretched yellow / dark red, the cloth white.
    const std::array<cv::Vec3b, kMarks> colour = {a.strain ? cv::Vec3b(235, 235, 235) : c,  // strain: white cloth
                                                  cv::Vec3b(230, 200, 0),
                                                  cv::Vec3b(200, 40, 200),
                                                  cv::Vec3b(40, 40, 220),
                                                  cv::Vec3b(160, 40, 20),
                                                  cv::Vec3b(240, 190, 120),
                                                  cv::Vec3b(40, 210, 250),
                                                  cv::Vec3b(20, 20, 140)};
    add_marked(g, mark, colour, meshes, colours);
    cv::Mat img = gdsr::render_meshes(meshes, colours, opt);
    draw_through(g, mark, colour, opt, img);
    if (body_crossing.F.rows() > 0)  // orange, drawn through the cloth
      draw_through(body_crossing, std::vector<int>(body_crossing.F.rows(), kIntersecting),
                   {cv::Vec3b(), cv::Vec3b(), cv::Vec3b(), cv::Vec3b(0, 140, 255)}, opt, img);
    return img;
  };
  const cv::Mat lr_img = render("LR", d.lr, lr, d.lr.layer, lr_c, lr_note),
                hr_img = render("HR", d.hr, hr, d.hr.layer, hr_c, hr_note);
  auto what = [&](const gdsr::TriMesh& g) {
    return a.layer >= 0 ? "layer " + std::to_string(a.layer) : std::to_string(g.num_vertices()) + " verts";
  };
  const cv::Mat img =
      gdsr::side_by_side({lr_img, hr_img}, {"LR " + what(lr) + ", frame " + std::to_string(t) + lr_note,
                                            "HR " + what(hr) + ", frame " + std::to_string(t) + hr_note});
  gdsr::write_png_atomic(a.out, img);
  std::printf("wrote %s (%d x %d): frame %d of %d, LR %d / HR %d vertices\n", a.out.c_str(), img.cols, img.rows, t, T,
              lr.num_vertices(), hr.num_vertices());
}

struct ImportArgs {
  gdsr::MdImportOptions opt;
  std::string out;
};

// True if `inner` is `outer` or inside it (absolute, normalised, symlinks resolved as far as
// they exist).
bool is_within(const std::string& inner, const std::string& outer) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path i = fs::weakly_canonical(fs::absolute(inner), ec), o = fs::weakly_canonical(fs::absolute(outer), ec);
  auto ii = i.begin();
  for (auto oi = o.begin(); oi != o.end(); ++oi, ++ii) {
    if (oi->empty()) continue;  // trailing "/"
    if (ii == i.end() || *ii != *oi) return false;
  }
  return true;
}

void run_import(const ImportArgs& a) {
  gdsr::check_dataset_out(a.out);
  for (const std::string* in : {&a.opt.lr_dir, &a.opt.hr_dir, &a.opt.body_dir, &a.opt.lr_uv, &a.opt.hr_uv})
    if (!in->empty() && (is_within(a.out, *in) || is_within(*in, a.out)))
      gdsr::fail("--out", a.out + " overlaps the input " + *in + "; write the dataset somewhere else");
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

struct CheckArgs {
  std::string data;
  std::string per_frame;  // non-empty: write each frame's figures to this CSV
  int intersection_stride = kDefaultIntersectionStride;
  bool body = true;
  bool strain_by_piece = false;  // also print the strain of each pattern piece
  double pinch_gap_mm = default_pinch_gap_mm();
};

// The strain of each piece of the pattern (UV island), averaged over the frames, for one
// resolution: where a garment's mean E_u comes from (a sleeve compressed along the arm, say).
void print_strain_by_piece(const char* res, const gdsr::GarmentMesh& g, const std::vector<gdsr::Points3>& frames) {
  const std::vector<int> piece = gdsr::pattern_pieces(g);
  const int n = piece.empty() ? 0 : 1 + *std::max_element(piece.begin(), piece.end());
  std::vector<gdsr::StrainEnergies> sum(n);
  for (const auto& X : frames) {
    const auto e = gdsr::strain_energies_by_piece(g, X, piece);
    for (int k = 0; k < n; ++k) {
      sum[k].E_u += e[k].E_u, sum[k].E_v += e[k].E_v, sum[k].E_uv += e[k].E_uv;
      sum[k].E_u_stretched += e[k].E_u_stretched, sum[k].E_v_stretched += e[k].E_v_stretched;
      sum[k].faces = e[k].faces;
    }
  }
  std::vector<double> x0(n, 1e300), x1(n, -1e300);
  for (int f = 0; f < g.FUV.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      x0[piece[f]] = std::min(x0[piece[f]], g.UV(g.FUV(f, c), 0));
      x1[piece[f]] = std::max(x1[piece[f]], g.UV(g.FUV(f, c), 0));
    }
  double total_u = 0;
  for (const auto& e : sum) total_u += e.E_u * e.faces;
  const double T = std::max<size_t>(1, frames.size());
  for (int k = 0; k < n; ++k) {
    const auto& e = sum[k];
    char range[64];
    std::snprintf(range, sizeof range, "%.2f-%.2f", x0[k], x1[k]);
    std::printf("  %-3s %5d %6d   %-11s %10.5f %10.5f %10.5f %10.5f %10.5f %8.1f%%\n", res, k, e.faces, range,
                e.E_u / T, e.E_u_stretched / T, e.E_v / T, e.E_v_stretched / T, e.E_uv / T,
                total_u > 0 ? 100.0 * e.E_u * e.faces / total_u : 0.0);
  }
}

// "same" if every number of `a` equals the one at the same place in `b` (relative 1e-9),
// else the path of the first difference.
std::string compare_json(const nlohmann::json& a, const nlohmann::json& b, const std::string& path = "") {
  if (a.is_object()) {
    if (!b.is_object()) return path;
    for (auto it = a.begin(); it != a.end(); ++it) {
      if (!b.contains(it.key())) return path + it.key();
      const std::string d = compare_json(it.value(), b[it.key()], path + it.key() + ".");
      if (d != "same") return d;
    }
    return "same";
  }
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    return std::abs(x - y) <= 1e-9 * std::max({1.0, std::abs(x), std::abs(y)}) ? "same"
                                                                               : path.substr(0, path.size() - 1);
  }
  return a == b ? "same" : path.substr(0, path.size() - 1);
}

void run_check(const CheckArgs& a) {
  const gdsr::Dataset d = gdsr::load_dataset(a.data);
  const auto& m = d.manifest;
  int covered = 0;
  for (int t : d.raster.tri) covered += t >= 0;
  std::printf("dataset %s: garment %s, %d layer(s), %d frames at %g fps (source %s)\n", a.data.c_str(),
              m.garment.c_str(), m.layers, m.frames, m.fps, m.source_motion.c_str());
  std::printf("  LR: %d vertices, %d faces, %d UV vertices (particle distance %.4g m)\n", m.lr_vertices, m.lr_faces,
              m.lr_uv_vertices, m.lr_particle_distance);
  std::printf("  HR: %d vertices, %d faces, %d UV vertices (particle distance %.4g m)\n", m.hr_vertices, m.hr_faces,
              m.hr_uv_vertices, m.hr_particle_distance);
  std::printf("  body: %d vertices, %d faces\n", m.body_vertices, m.body_faces);
  std::printf("  UV raster: %d x %d, %.1f%% of pixels covered\n", d.raster.width, d.raster.height,
              100.0 * covered / std::max<size_t>(1, d.raster.tri.size()));
  std::fflush(stdout);
  if (m.frames > 0) {
    gdsr::ValidityOptions vo;
    vo.intersection_stride = a.intersection_stride;
    vo.body = a.body;
    vo.pinch_gap = 1e-3 * a.pinch_gap_mm;
    double seconds = 0;
    const gdsr::ValidityFigures v = measure(d, vo, seconds);
    std::printf("%s", gdsr::validity_table(v).c_str());
    std::printf("  (validity figures: %.1f s)\n", seconds);
    if (a.strain_by_piece) {
      std::printf("strain by pattern piece (UV islands, numbered left to right in the pattern), means over %d frames\n",
                  m.frames);
      std::printf(
          "  res piece  faces   UV x (m)           E_u  stretched        E_v  stretched       E_uv  share of E_u\n");
      print_strain_by_piece("LR", d.lr, d.lr_frames);
      print_strain_by_piece("HR", d.hr, d.hr_frames);
    }
    if (!a.per_frame.empty()) {
      gdsr::write_text_atomic(a.per_frame, gdsr::validity_per_frame_csv(v));
      std::printf("  per-frame figures: %s\n", a.per_frame.c_str());
    }
    if (m.validity.empty()) {
      std::printf("  manifest: no validity figures stored\n");
    } else {
      const gdsr::ValidityFigures stored = gdsr::validity_from_json(m.validity);
      if (stored.intersection_stride != v.intersection_stride || stored.body_measured != v.body_measured)
        std::printf("  manifest: validity figures stored with stride %d%s; not compared\n", stored.intersection_stride,
                    stored.body_measured ? " and the body" : " and no body");
      else if (stored.body_measured && std::abs(stored.pinch_gap - v.pinch_gap) > 1e-9)
        std::printf(
            "  manifest: validity figures stored with a pinch gap of %.1f mm (0: before the crease rule); not "
            "compared\n",
            1e3 * stored.pinch_gap);
      else {
        // Over the stored keys: a manifest written before a figure existed still compares.
        const std::string diff = compare_json(m.validity, gdsr::validity_to_json(v));
        if (diff == "same")
          std::printf("  manifest: stored validity figures agree with the recomputed ones\n");
        else
          std::printf("  manifest: stored validity figures DIFFER from the recomputed ones (first at '%s')\n",
                      diff.c_str());
      }
    }
  }
  std::printf("ok\n");
}

}  // namespace

void add_data_command(CLI::App& app) {
  CLI::App* data =
      app.add_subcommand("data", "make, preview, import, check, compare and tabulate paired LR/HR datasets");
  data->require_subcommand(1);

  auto mk = std::make_shared<MakeArgs>();
  CLI::App* make = data->add_subcommand("make", "simulate a garment at LR and HR on a motion and write a dataset");
  make->add_option("--garment", mk->garment, "garment name")
      ->capture_default_str()
      ->check(CLI::IsMember(sim::garment_names()));
  make->add_option("--motion", mk->motion, "motion file (BVH, FBX, glTF, Collada)")->capture_default_str();
  make->add_option("--out", mk->out, "dataset folder to write (atomically)")->required();
  // Bounds keep a run finite: a finer particle distance or a higher frame rate than these
  // would simulate for hours (vertex count grows as 1/pd^2).
  make->add_option("--lr-pd", mk->lr_pd, "LR particle distance, metres")
      ->capture_default_str()
      ->check(finite_range(kMinParticleDistance, kMaxParticleDistance));
  make->add_option("--hr-pd", mk->hr_pd, "HR particle distance, metres (not coarser than --lr-pd)")
      ->capture_default_str()
      ->check(finite_range(kMinParticleDistance, kMaxParticleDistance));
  make->add_option("--seconds", mk->seconds, "clip length in seconds (after the rest blend)")
      ->capture_default_str()
      ->check(finite_range(1e-3, 3600.0));
  make->add_option("--start", mk->start, "clip start in seconds")->capture_default_str()->check(finite_range(0.0, 1e6));
  make->add_option("--fps", mk->fps, "frames per second")->capture_default_str()->check(finite_range(1.0, kMaxFps));
  make->add_option("--substeps", mk->substeps, "solver substeps per frame (default: the solver's)")
      ->check(CLI::Range(1, 1000));
  make->add_option("--substep-travel", mk->substep_travel,
                   "metres: a frame takes more substeps (up to --max-substeps) when its fastest vertex would move "
                   "farther than this in one, relative to the cloth's mean; 0: always --substeps (default: the "
                   "solver's, sim::SimParams::substep_travel)")
      ->check(finite_range(0.0, 1.0));
  make->add_option("--max-substeps", mk->max_substeps, "most substeps a frame takes with --substep-travel")
      ->check(CLI::Range(1, 1000));
  make->add_option("--iterations", mk->iterations, "constraint passes per substep (default: the solver's)")
      ->check(CLI::Range(1, 100));
  make->add_option("--stretch-passes", mk->stretch_passes, "stretch passes per iteration (default: the solver's)")
      ->check(CLI::Range(1, 100));
  make->add_option("--friction", mk->friction, "Coulomb friction against the body (default: the solver's)")
      ->check(finite_range(0.0, 2.0));
  make->add_option("--bend-stiffness", mk->bend_stiffness, "bending modulus, N m (default: the solver's)")
      ->check(finite_range(0.0, 1.0));
  make->add_option("--self-thickness", mk->self_thickness,
                   "least cloth-cloth distance kept, metres (default: the solver's; the solver also keeps 1/6 of the "
                   "particle distance)")
      ->check(finite_range(0.0, 0.05));
  make->add_option("--self-slack", mk->self_slack,
                   "metres a vertex may leave its predicted path before self-contacts are re-detected"
                   " (default: the solver's; smaller is faster on smooth cloth, re-detects more in fast folds)")
      ->check(finite_range(1e-5, 0.05));
  make->add_option("--self-slack-per-pd", mk->self_slack_per_pd,
                   "the slack is at most this fraction of the particle distance, and --self-detect-every grows as it"
                   " shrinks (default: the solver's; 10 lifts the cap, as before solver revision 8)")
      ->check(finite_range(1e-3, 10.0));
  make->add_option("--self-detect-every", mk->self_detect_every,
                   "substeps between self-contact detections (default: the solver's)")
      ->check(CLI::Range(1, 1000));
  make->add_option("--self-passes", mk->self_passes,
                   "self-contact passes per iteration, stopping early when no contact is violated (default: the "
                   "solver's)")
      ->check(CLI::Range(1, 100));
  make->add_option("--compression-ratio", mk->compression_ratio,
                   "in-plane compression stiffness / stretch stiffness at a 10 mm particle distance, scaled by (0.01 m "
                   "/ pd)^k, k: --compression-exponent (default: the solver's)")
      ->check(finite_range(1e-4, 1.0));
  make->add_option("--compression-exponent", mk->compression_exponent,
                   "k above (default: the solver's, 2, the Euler buckling load; 1: a 30 mm mesh 3x stiffer in "
                   "compression, its strain within 2x of a 10 mm one's; 0: one ratio at every particle distance)")
      ->check(finite_range(0.0, 4.0));
  make->add_option("--untangle-step", mk->untangle_step,
                   "per substep, the most cloth that went through itself is moved to undo it, in self-thicknesses "
                   "(default: the solver's; 0: off, as before solver revision 12)")
      ->check(finite_range(0.0, 1.0));
  make->add_option(
          "--max-push-step", mk->max_push_step,
          "metres per contact pass (one per iteration): how much farther than the body's surface a body contact "
          "moves cloth that hangs from no pin (default: the solver's; 1: at once, as before solver revision 15)")
      ->check(finite_range(1e-5, 1.0));
  make->add_option("--pinch-separation", mk->pinch_separation,
                   "metres: body points this far apart in the first pose are different parts, cloth pinched "
                   "between them stays on the part it was dressed on (default: the solver's)")
      ->check(finite_range(0.01, 1.0));
  make->add_option("--dressed-radius", mk->dressed_radius,
                   "metres: body points this close to where some cloth was dressed (its closest body point in the "
                   "first pose) are under the garment, and only parts outside it pass through pinned cloth (default: "
                   "the solver's; 0: every part far from the cloth's own, as before solver revision 29)")
      ->check(finite_range(0.0, 1.0));
  make->add_option("--track-rate", mk->track_rate,
                   "1/s: HR follows the LR simulation at the LR scale, a difference in drape decaying at this rate, "
                   "and adds finer wrinkles (default: the solver's, 30; 0: independent, as before revision 13)")
      ->check(finite_range(0.0, 1000.0));
  make->add_option("--contact-every", mk->contact_every,
                   "substeps between body contact refreshes (default: the garment's, " +
                       std::to_string(sim::body_contact_every("tshirt", sim::SimParams().contact_every)) +
                       " for the t-shirt, else the solver's, " + std::to_string(sim::SimParams().contact_every) + ")")
      ->check(CLI::Range(1, 1000));
  make->add_option(
          "--contact-travel", mk->contact_travel,
          "the body contact search reaches this many times the distance a vertex travels until the next "
          "refresh beyond the fixed radius (default: the solver's, 1; 0: the fixed radius, solver revision 22)")
      ->check(finite_range(0.0, 10.0));
  make->add_option("--pin-yield-rate", mk->pin_yield_rate,
                   "1/s: a body part other than the one a pin was dressed on may press the pin towards the body, "
                   "and it returns at this rate (default: the solver's, 5; 0: rigid pins; one-layer garments only)")
      ->check(finite_range(0.0, 1000.0));
  make->add_option("--settle-frames", mk->settle_frames,
                   "frames of damped motion on the first pose before frame 0 (default: the solver's)")
      ->check(CLI::Range(0, 1000));
  make->add_flag("!--no-self-collision", mk->self_collision, "switch cloth self-collision off");
  make->add_flag("!--no-self-redetect", mk->self_redetect,
                 "find every self-contact pair again whenever a vertex leaves its slack, not only that vertex's "
                 "(solver revision 21; slower, the same pairs where it matters)");
  make->add_flag("--tangle-retest", mk->self_tangle_retest,
                 "look for cloth through itself also after a substep whose self-contact pass pushed pairs back "
                 "across, not only once a frame (sim::SimParams::self_tangle_retest has the trade)");
  make->add_flag("--refuse-crossing-push", mk->self_refuse_crossing_push,
                 "refuse a self-contact push back to a pair's remembered side that would make the cloth's faces "
                 "intersect; the pair takes the side it is on (sim::SimParams::self_refuse_crossing_push has the "
                 "trade)");
  make->add_flag("!--no-limbs-pass-through", mk->limbs_pass_through,
                 "keep body contacts around cloth that a hand went through, so the hand carries it (solver "
                 "revision 10)");
  make->add_flag("!--no-limbs-pass-until-clear", mk->limbs_pass_until_clear,
                 "put cloth that a hand went through back in full contact with the hand once it is less "
                 "than 2 cm inside, so the hand pushes it on (solver revision 16)");
  make->add_flag("--independent-hr", mk->independent_hr,
                 "settle the HR garment from its own placement instead of from the settled LR garment (solver "
                 "revision 3; the resolutions then start the clip with their folds in different places)");
  make->add_flag("--skip-built", mk->skip_built,
                 "keep --out if it already holds this clip (garment, motion, range, particle distances), built by "
                 "this solver revision and valid (a recipe always does this)");
  make->add_option("--arm-clearance", mk->arm_clearance,
                   "metres: an upper arm coming closer than this to the trunk or legs (mocap arms pass through "
                   "the body) is turned out at the shoulder just enough, eased over 0.2 s; 0: the motion as in "
                   "the file")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.1));
  make->add_option("--body-yield-gap", mk->body_yield_gap,
                   "metres: where skinning drives one body part into another (a thigh raised into the belly), "
                   "both surfaces give way, each half the overlap, to meet this far apart, as flesh does; 0: "
                   "the skinned surface as it is")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.049));
  make->add_option("--min-shoulder-half-width", mk->min_shoulder_half_width,
                   "metres: a skeleton whose shoulder joints are closer than this to the middle has them moved "
                   "out to it (the CMU salsa BVHs' 0.126 m hang the arms inside the trunk); 0: as in the file")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.3));
  make->add_option("--rest-blend", mk->rest_blend_frames, "frames blending from the rest pose")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  make->add_option("--raster", mk->raster, "UV raster size in pixels")
      ->capture_default_str()
      ->check(CLI::Range(kMinRaster, kMaxRaster));
  make->add_option("--intersection-stride", mk->intersection_stride, "count self-intersections on every k-th frame")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  auto* recipe = make->add_option("--recipe", mk->recipe,
                                  "dataset recipe (JSON: garments x clips, train / held-out split, see "
                                  "configs/recipe_paper.json): builds each clip into --out/<name>, skipping those "
                                  "already built and valid; an interrupted run continues where it stopped");
  for (const char* flag :
       {"--garment", "--motion", "--lr-pd", "--hr-pd", "--seconds", "--start", "--fps", "--rest-blend"})
    recipe->excludes(make->get_option(flag));
  make->callback([mk]() {
    if (mk->recipe.empty())
      run_make(*mk);
    else
      run_recipe(*mk);
  });

  auto pv = std::make_shared<PreviewArgs>();
  CLI::App* prev = data->add_subcommand("preview", "render LR and HR of one frame side by side to a PNG");
  prev->add_option("--data", pv->data, "dataset folder")->required();
  prev->add_option("--frame", pv->frame, "frame index (default, -1: the last)")->check(CLI::Range(-1, 1 << 30));
  prev->add_option("--out", pv->out, "PNG file to write")->required();
  prev->add_option("--size", pv->size, "pixels per image side")->capture_default_str()->check(CLI::Range(16, 8192));
  prev->add_flag("!--no-body", pv->body, "leave the body out");
  prev->add_flag("--intersections", pv->intersections,
                 "paint faces in self-intersecting pairs (CGAL) red, drawn through the cloth and body that hide them");
  prev->add_flag("--penetration", pv->penetration,
                 "paint faces with a corner more than 5 mm inside the body magenta, cyan where a second body part "
                 "or a closed crease pinches it (the rule of `data check`), drawn through the body");
  add_pinch_gap_option(prev, pv->pinch_gap_mm, "with --penetration, as for `data check`: ");
  prev->add_flag("--strain", pv->strain,
                 "paint faces by their most strained fibre against the pattern: more than 2% / 5% shorter light / dark "
                 "blue, longer yellow / dark red, the rest of the cloth white (under the marks of --intersections and "
                 "--penetration)");
  std::vector<std::string> view_names;
  for (const View& v : kViews) view_names.push_back(v.name);
  prev->add_option("--view", pv->view, "camera on the body's front, back, left, right or top")
      ->capture_default_str()
      ->check(CLI::IsMember(view_names));
  prev->add_option("--layer", pv->layer,
                   "draw only this cloth layer (0: innermost; -1: all), to see between the layers of a layered garment")
      ->capture_default_str()
      ->check(CLI::Range(-1, 1 << 20));
  prev->callback([pv]() { run_preview(*pv); });

  auto imp = std::make_shared<ImportArgs>();
  CLI::App* im = data->add_subcommand("import-md", "import Marvelous Designer per-frame OBJ exports");
  im->add_option("--lr-dir", imp->opt.lr_dir, "folder of per-frame LR (30 mm) OBJs")->required();
  im->add_option("--hr-dir", imp->opt.hr_dir, "folder of per-frame HR (10 mm) OBJs")->required();
  im->add_option("--lr-uv", imp->opt.lr_uv, "flattened (UV) LR OBJ")->required();
  im->add_option("--hr-uv", imp->opt.hr_uv, "flattened (UV) HR OBJ")->required();
  im->add_option("--body-dir", imp->opt.body_dir, "folder of per-frame body OBJs (optional)");
  im->add_option("--garment", imp->opt.garment, "garment name")->capture_default_str();
  im->add_option("--fps", imp->opt.fps, "frames per second of the exports")
      ->capture_default_str()
      ->check(finite_range(1.0, kMaxFps));
  im->add_option("--scale", imp->opt.scale, "file units to metres (0.001 for mm)")
      ->capture_default_str()
      ->check(finite_range(1e-6, 1e6));
  im->add_option("--weld", imp->opt.weld, "merge 3-D vertices closer than this (metres) for unwelded exports")
      ->check(finite_range(0.0, 1.0));
  im->add_option("--out", imp->out, "dataset folder to write")->required();
  im->callback([imp]() { run_import(*imp); });

  auto chk = std::make_shared<CheckArgs>();
  CLI::App* ch = data->add_subcommand("check", "load a dataset, validate it, print its counts and validity figures");
  ch->add_option("--data", chk->data, "dataset folder")->required();
  ch->add_option("--intersection-stride", chk->intersection_stride, "count self-intersections on every k-th frame")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  ch->add_flag("!--no-body", chk->body, "do not measure the body penetration");
  add_pinch_gap_option(ch, chk->pinch_gap_mm, "");
  ch->add_option("--per-frame", chk->per_frame,
                 "also write each frame's figures to this CSV (intersecting pairs, depth outside pinches, agreement)");
  ch->add_flag("--strain-by-piece", chk->strain_by_piece,
               "also print E_u, E_v and E_uv of each piece of the pattern (UV island), LR and HR, over the clip");
  ch->callback([chk]() { run_check(*chk); });

  add_data_compare_command(*data);
  add_data_table_command(*data);
}

// Cloth solver speed vs accuracy: skirt_short on 40 frames of CMU 01_01 from 1 s (the first 15
// blend from the rest pose, as in a dataset; an analytic swaying mannequin without the file)
// at LR (30 mm) and HR (10 mm), for several substep / iteration / self-contact detection
// settings (slack: how far a vertex may leave its predicted path before re-detection; detect:
// substeps between detections; thick: the self-contact thickness; contact_every: substeps
// between body contact refreshes; redetect: only the pairs of a vertex that left its slack are
// found again, or all; retest: the tangle test also after a substep that pushed pairs back
// across, or once a frame; travel: adaptive substeps, SimParams::substep_travel, 0: fixed), with and without
// self-collision. Every setting starts from
// the drape `gdsr data make` starts its clip from (the first pose's settle with the default
// solver, HR from the upsampled LR drape), so the figures are those of a dataset, and the
// settle is not timed. Run with OMP_NUM_THREADS=1 and 2 to see the threads' gain. Counters
// next to the time: seconds per clip frame, vertices, the paper's stretch/shear energies
// (mean over frames), max body penetration, mean curvature (wrinkle measure, 1/m),
// self-intersecting non-adjacent triangle pairs counted by CGAL (mean over every 4th frame,
// and the fraction of those frames that are clean) and the RMS position error at the last
// frame against a reference run from the same drape with 40 substeps x 4 passes (metres).
#include <benchmark/benchmark.h>

#include "gdsr/body/body.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "tests/support/cloth_bodies.hpp"
#include "gdsr/sim/cloth_solver.hpp"
#include "gdsr/sim/garments.hpp"
#include "gdsr/geometry/self_intersections.hpp"
#include "gdsr/sim/sim_metrics.hpp"

#include <chrono>
#include <ctime>
#include <cmath>
#include <filesystem>
#include <map>

namespace {

struct Scene {
  gdsr::Faces F;
  std::vector<gdsr::Points3> frames;
  gdsr::TriMesh rest;
  double fps = 30;
};

const Scene& scene() {
  static Scene s = [] {
    Scene sc;
    const std::string bvh = "/usr/share/assimp/models/BVH/01_01.bvh";
    const int nframes = 40;
    if (std::filesystem::exists(bvh)) {
      gdsr::BodyOptions opt;
      opt.start_seconds = 1;
      opt.max_seconds = 1;
      auto body = gdsr::load_body_sequence(bvh, opt);
      sc.F = body.F;
      sc.rest = body.rest_mesh();
      for (int t = 0; t < nframes && t < body.num_frames(); ++t) sc.frames.push_back(body.frames[t]);
      sc.fps = body.fps;
    } else {
      sc.rest = sim::make_mannequin(1.7);
      sc.F = sc.rest.F;
      for (int t = 0; t < nframes; ++t) {
        gdsr::Points3 V = sc.rest.V;
        V.col(0).array() += 0.08 * std::sin(2 * M_PI * t / 30.0);
        sc.frames.push_back(V);
      }
    }
    return sc;
  }();
  return s;
}

const sim::Garment& garment(int mm) {
  static std::map<int, sim::Garment> cache;
  auto it = cache.find(mm);
  if (it == cache.end()) it = cache.emplace(mm, sim::make_garment("skirt_short", mm / 1000.0, scene().rest)).first;
  return it->second;
}

// The clip's first frame as `gdsr data make` makes it: settled on the first pose with the
// default solver; HR settles from the upsampled LR drape.
const gdsr::Points3& start(int mm) {
  static std::map<int, gdsr::Points3> cache;
  auto it = cache.find(mm);
  if (it != cache.end()) return it->second;
  const std::vector<gdsr::Points3> first{scene().frames.front()};
  const gdsr::Points3 lr = sim::simulate_frames(garment(30), scene().F, first, scene().fps, sim::SimParams()).front();
  gdsr::Points3 x = lr;
  if (mm != 30) {
    const gdsr::Points3 up = gdsr::upsample(gdsr::compute_correspondence(garment(30).mesh, garment(mm).mesh), lr);
    x = sim::simulate_frames(garment(mm), scene().F, first, scene().fps, sim::SimParams(), {}, &up).front();
  }
  return cache.emplace(mm, x).first->second;
}

// slack_m > 0: that self-contact slack at every particle distance with detect_every (the
// solver before revision 8); thickness_m > 0: that self-contact thickness; 0: the solver's defaults.
std::vector<gdsr::Points3> run(int mm, int substeps, int iterations, bool self_collision, double slack_m = 0,
                               int detect_every = 0, double thickness_m = 0, int contact_every = 0,
                               bool redetect = true, bool retest = false, double travel_m = 0,
                               double* substeps_per_frame = nullptr) {
  sim::SimParams p;
  p.substep_travel = travel_m;  // 0: `substeps` every frame
  p.self_redetect = redetect;
  p.self_tangle_retest = retest;
  p.substeps = substeps;
  p.iterations = iterations;
  p.self_collision = self_collision;
  if (slack_m > 0) {
    p.self_slack = slack_m;
    p.self_slack_per_pd = 10;  // no cap
    p.self_detect_every = detect_every;
  }
  if (thickness_m > 0) p.self_thickness = thickness_m;
  if (contact_every > 0) p.contact_every = contact_every;
  p.settle_frames = 0;  // from the settled drape
  return sim::simulate_frames(garment(mm), scene().F, scene().frames, scene().fps, p, {}, &start(mm), nullptr,
                              substeps_per_frame);
}

const gdsr::Points3& reference(int mm) {
  static std::map<int, gdsr::Points3> cache;
  auto it = cache.find(mm);
  if (it == cache.end()) it = cache.emplace(mm, run(mm, 40, 4, true).back()).first;
  return it->second;
}

void BM_ClothSkirtShort(benchmark::State& state) {
  const int mm = static_cast<int>(state.range(0));
  const int substeps = static_cast<int>(state.range(1));
  const int iterations = static_cast<int>(state.range(2));
  const bool self_collision = state.range(3) != 0;
  const double slack = state.range(4) * 1e-4;  // 0.1 mm units
  const int detect_every = static_cast<int>(state.range(5));
  const double thickness = state.range(6) * 1e-4;  // 0.1 mm units
  const int contact_every = static_cast<int>(state.range(7));  // 0: the solver's
  const bool redetect = state.range(8) != 0;
  const bool retest = state.range(9) != 0;
  const double travel = state.range(10) * 1e-4;  // 0.1 mm units; 0: fixed substeps
  const auto& sc = scene();
  const auto& g = garment(mm);
  const auto& ref = reference(mm);
  std::vector<gdsr::Points3> out;
  double seconds = 0, cpu = 0, substeps_per_frame = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    out = run(mm, substeps, iterations, self_collision, slack, detect_every, thickness, contact_every, redetect, retest,
              travel, &substeps_per_frame);
    cpu += static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  const auto m = sim::sequence_metrics(g.mesh, out, sc.F, sc.frames, sc.fps);
  double eu = 0, ev = 0, euv = 0, pen = 0;
  for (const auto& f : m) {
    eu += f.strain.E_u / m.size();
    ev += f.strain.E_v / m.size();
    euv += f.strain.E_uv / m.size();
    pen = std::max(pen, f.penetration.max_depth);
  }
  state.counters["verts"] = static_cast<double>(g.mesh.V.rows());
  state.counters["substeps_per_frame"] = substeps_per_frame;
  // Wall time and process CPU time (the solver is single-threaded, so CPU time is its cost
  // on an idle core even when the machine is loaded).
  state.counters["s_per_frame"] = seconds / state.iterations() / (sc.frames.size() - 1);
  state.counters["cpu_s_per_frame"] = cpu / state.iterations() / (sc.frames.size() - 1);
  state.counters["E_u"] = eu;
  state.counters["E_v"] = ev;
  state.counters["E_uv"] = euv;
  state.counters["pen_max_m"] = pen;
  state.counters["curvature"] = m.back().wrinkles.mean_curvature;
  state.counters["dihedral"] = m.back().wrinkles.mean_dihedral;
  double isect = 0;
  int checked = 0, clean = 0;
  for (size_t t = 0; t < out.size(); t += 4, ++checked) {
    const auto n = gdsr::self_intersections(out[t], g.mesh.F).pairs;
    isect += static_cast<double>(n);
    clean += n == 0;
  }
  state.counters["isect_pairs"] = isect / checked;
  state.counters["clean_frac"] = static_cast<double>(clean) / checked;
  state.counters["rms_vs_ref_m"] = std::sqrt((out.back() - ref).rowwise().squaredNorm().mean());
}

}  // namespace

BENCHMARK(BM_ClothSkirtShort)
    ->Args({30, 40, 1, 0, 0, 0, 0, 0, 1, 0, 0})  // the former default: no self-collision, one pass
    // The default: at least 20 substeps, more where the fastest vertex would move > 3 mm in one
    // (SimParams::substep_travel); then 20 fixed, the default before solver revision 32.
    ->Args({30, 20, 2, 1, 0, 0, 0, 0, 1, 0, 30})
    ->Args({30, 20, 2, 1, 0, 0, 0, 0, 1, 0, 0})
    ->Args({30, 10, 2, 1, 0, 0, 0, 0, 1, 0, 0})
    ->Args({30, 20, 4, 1, 0, 0, 0, 0, 1, 0, 0})
    ->Args({10, 40, 1, 0, 0, 0, 0, 0, 1, 0, 0})
    // The default: slack 1.5 mm, detected at most every 8 substeps, 5 mm thick, adaptive
    // substeps; then 20 fixed.
    ->Args({10, 20, 2, 1, 0, 0, 0, 0, 1, 0, 30})
    ->Args({10, 20, 2, 1, 0, 0, 0, 0, 1, 0, 0})
    ->Args({10, 10, 2, 1, 0, 0, 0, 0, 1, 0, 0})
    // The 10 mm default before solver revision 8: the 30 mm mesh's 3 mm slack, detected at most
    // every 4 substeps. The same figures in 1.7x the time (SimParams::self_slack_per_pd).
    ->Args({10, 20, 2, 1, 30, 4, 0, 0, 1, 0, 0})
    // The 10 mm default before solver revision 18: 3 mm thick (SimParams::self_thickness).
    ->Args({10, 20, 2, 1, 0, 0, 30, 0, 1, 0, 0})
    // Body contacts found every substep instead of every 5th (SimParams::contact_every): a fast
    // limb cannot overtake the cloth between two refreshes. On this walk: 1.8x (30 mm) and 1.4x
    // (10 mm) the CPU time for the same figures (no penetration either way, RMS from the
    // reference 17.6 against 15.9 mm and 28.9 against 28.8 mm), so 5 stays the default. Every 3rd:
    // the t-shirt's (sim::body_contact_every, for its sleeves in a bending elbow's crook); on this
    // walk 1.07x the CPU time at both 30 mm (0.050 s a frame) and 10 mm (0.66 s), the same figures
    // (RMS from the reference 15.9 and 28.8 mm, every 4th frame free of self-intersections).
    ->Args({30, 20, 2, 1, 0, 0, 0, 1, 1, 0, 0})
    ->Args({10, 20, 2, 1, 0, 0, 0, 1, 1, 0, 0})
    ->Args({30, 20, 2, 1, 0, 0, 0, 3, 1, 0, 0})
    ->Args({10, 20, 2, 1, 0, 0, 0, 3, 1, 0, 0})
    // A full detection whenever a vertex leaves its slack, as before solver revision 22, instead
    // of finding only its pairs again (SimParams::self_redetect).
    ->Args({30, 20, 2, 1, 0, 0, 0, 0, 0, 0, 0})
    ->Args({10, 20, 2, 1, 0, 0, 0, 0, 0, 0, 0})
    // The tangle test also after a substep that pushed pairs back across, not only once a frame
    // (SimParams::self_tangle_retest, off by default).
    ->Args({30, 20, 2, 1, 0, 0, 0, 0, 1, 1, 0})
    ->Args({10, 20, 2, 1, 0, 0, 0, 0, 1, 1, 0})
    ->ArgNames({"mm", "substeps", "iterations", "self", "slack_0.1mm", "detect", "thick_0.1mm", "contact_every",
                "redetect", "retest", "travel_0.1mm"})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

BENCHMARK_MAIN();

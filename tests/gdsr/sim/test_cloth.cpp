#include <doctest/doctest.h>

#include "gdsr/body/body.hpp"
#include "gdsr/body/body_query.hpp"
#include "gdsr/error.hpp"
#include "tests/support/cloth_bodies.hpp"
#include "tests/support/square_cloth.hpp"
#include "gdsr/sim/cloth_solver.hpp"
#include "gdsr/sim/garments.hpp"
#include "gdsr/sim/pattern.hpp"
#include "gdsr/sim/sim_metrics.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <omp.h>
#include <utility>

using gdsr::Points3;
using gdsr::Vec2;
using gdsr::Vec3;

namespace {

using gdsr_test::square_cloth;

double signed_volume(const gdsr::TriMesh& m) {
  double v = 0;
  for (int f = 0; f < m.F.rows(); ++f)
    v += Vec3(m.V.row(m.F(f, 0))).dot(Vec3(m.V.row(m.F(f, 1))).cross(Vec3(m.V.row(m.F(f, 2))))) / 6;
  return v;
}

}  // namespace

TEST_CASE("cloth: analytic bodies are closed and outward") {
  auto s = sim::make_sphere(Vec3(0, 0, 0), 0.2);
  CHECK(signed_volume(s) == doctest::Approx(4.0 / 3 * M_PI * 0.008).epsilon(0.02));
  auto c = sim::make_capsule(0, 0, 0, 1, 0.1);
  CHECK(signed_volume(c) == doctest::Approx(M_PI * 0.01 * 0.8 + 4.0 / 3 * M_PI * 0.001).epsilon(0.02));
}

TEST_CASE("cloth: a flat cloth without gravity or body stays exactly at rest") {
  // Checks that the stretch and bending constraints vanish on the flat rest shape.
  auto g = square_cloth(0.4, 0.03, 0.0);
  sim::SimParams p;
  p.gravity = Vec3::Zero();
  sim::ClothSolver solver(g, gdsr::Faces(), Points3(), p);
  CHECK(solver.num_bends() > 100);
  for (int t = 0; t < 10; ++t) solver.step(Points3(), Points3(), 1.0 / 30);
  CHECK((solver.positions() - g.mesh.V).cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("cloth: a square draped on a sphere comes to rest without penetration") {
  const double r = 0.2;
  auto sphere = sim::make_sphere(Vec3(0, 0, 0), r, 32, 64);
  auto g = square_cloth(0.7, 0.025, r + 0.03);
  sim::SimParams p;
  p.settle_frames = 0;
  p.substeps = 20;
  p.damping = 2.0;
  std::vector<Points3> frames(90, sphere.V);  // 3 s at 30 fps, static body
  auto out = sim::simulate_frames(g, sphere.F, frames, 30.0, p);
  REQUIRE(out.size() == frames.size());
  const auto& X = out.back();
  REQUIRE(X.allFinite());
  auto pen = sim::body_penetration(X, sphere.F, sphere.V);
  CAPTURE(pen.max_depth);
  CHECK(pen.max_depth < 0.5 * p.thickness);  // the sphere mesh's chords sit inside the true sphere
  // The cloth lies on the sphere: its centre vertex rests on top at r + thickness.
  int centre = 0;
  for (int v = 0; v < X.rows(); ++v)
    if (Vec2(g.mesh.V(v, 0), g.mesh.V(v, 2)).norm() < Vec2(g.mesh.V(centre, 0), g.mesh.V(centre, 2)).norm()) centre = v;
  CHECK(X(centre, 1) == doctest::Approx(r + p.thickness).epsilon(0.05));
  // The rim hangs below the equator-ish (draped, not flat).
  CHECK(X.col(1).minCoeff() < 0.0);
  const double ke = sim::kinetic_energy(g.mesh, out[out.size() - 2], X, 1.0 / 30);
  double mass = 0;
  const sim::ClothSolver probe(g, sphere.F, sphere.V, p);
  for (double m : probe.masses()) mass += m;
  CAPTURE(ke);
  CHECK(ke < 0.5 * mass * 0.03 * 0.03);  // rms speed below 3 cm/s (creeping folds)
  auto se = gdsr::strain_energies(g.mesh, X);
  CHECK(se.E_u < 0.01);
  CHECK(se.E_v < 0.01);
}

namespace {
// A square draped on a "torso" sphere (r = 0.2) while a "hand" sphere (r = 0.05) that starts
// 0.35 m above comes down onto it and sinks 1 cm into the torso, pinching the cloth (frames
// 30-44), slides 0.5 rad along the torso still sunk in (45-59) and rises (60-74).
struct Pinch {
  double depth = 0;  // deepest cloth vertex inside the true torso sphere when the hand has come down, metres
  double drag = 0;   // how far the slide moved the cloth's centroid, metres
};
Pinch pinch_scene(double pinch_separation) {
  const double r = 0.2, rh = 0.05, R = r + rh - 0.01;
  const auto torso = sim::make_sphere(Vec3(0, 0, 0), r, 32, 64);
  const auto hand0 = sim::make_sphere(Vec3(0, 0, 0), rh, 12, 24);
  const auto body = sim::merge_meshes(torso, hand0);
  auto g = square_cloth(0.5, 0.025, r + 0.03);
  sim::SimParams p;
  p.settle_frames = 0;
  p.damping = 2.0;
  p.pinch_separation = pinch_separation;
  std::vector<Points3> frames;
  for (int t = 0; t < 75; ++t) {
    const double down = std::clamp((t - 30) / 14.0, 0.0, 1.0), slide = std::clamp((t - 45) / 14.0, 0.0, 1.0);
    const double up = std::clamp((t - 60) / 14.0, 0.0, 1.0), a = 0.5 * slide;
    const Vec3 on(R * std::sin(a), R * std::cos(a), 0);
    const Vec3 c = t < 60 ? Vec3(Vec3(0, 0.6 + down * (R - 0.6), 0) + on - Vec3(0, R, 0))
                          : Vec3(on + Vec3(0, up * (0.6 - on.y()), 0));
    Points3 V = body.V;
    V.bottomRows(hand0.V.rows()).rowwise() += c.transpose();
    frames.push_back(V);
  }
  const auto out = sim::simulate_frames(g, body.F, frames, 30.0, p);
  Pinch s;
  s.depth = -1;
  for (int v = 0; v < out[44].rows(); ++v) s.depth = std::max(s.depth, r - out[44].row(v).norm());
  s.drag = (out.back().colwise().mean() - out[44].colwise().mean()).norm();
  REQUIRE(out.back().allFinite());
  return s;
}
}  // namespace

TEST_CASE("cloth: cloth pinched between a hand and the torso stays on the torso") {
  // Both parts cannot be kept out; the part the cloth was dressed on wins (pinch_separation),
  // so the hand sinks through the cloth instead of pressing it into the torso. Tolerance 2 mm:
  // the 32-ring sphere's chords lie up to 1 mm inside the true sphere. Measured 1.63 mm with
  // the adaptive substeps of solver revision 32, under 1.5 mm (the bound until then) at 20
  // fixed substeps; 12 mm without telling the parts apart (below).
  const Pinch with = pinch_scene(0.15);
  MESSAGE("telling parts apart: depth " << 1e3 * with.depth << " mm, drag " << 1e3 * with.drag << " mm");
  CHECK(with.depth < 0.002);
  // Not asserted: a hand that slides while sunk into the torso still ploughs the cloth along
  // (22 mm here since solver revision 15, 39 mm before; 57 mm without telling the parts apart;
  // 0.3 mm without a hand). Letting the hand pass through where there is no room fixed this
  // scene (2 mm) but made 01_01 agree worse (29.9 against 24.6 mm over 1 s), so it is not in
  // the solver.
  // Without telling the parts apart the nearest part (the hand) wins: the cloth is pushed
  // into the torso. The test can fail.
  const Pinch without = pinch_scene(100.0);
  MESSAGE("nearest part only: depth " << 1e3 * without.depth << " mm, drag " << 1e3 * without.drag << " mm");
  CHECK(without.depth > 0.005);
}

namespace {
// Deepest any vertex of a 16 cm sheet gets inside a static sphere (r = 0.15 m; metres, from the
// true sphere) when it falls onto it from 0.3 m above under 30 g, arriving at ~13 m/s: 11 cm
// between two contact refreshes, more than the fixed search radius (34 mm) and max_push (20 mm)
// together.
double deepest_in_sphere_after_fast_fall(double contact_travel) {
  const double r = 0.15;
  const auto sphere = sim::make_sphere(Vec3(0, 0, 0), r, 32, 64);
  auto g = square_cloth(0.16, 0.02, r + 0.3);
  sim::SimParams p;
  p.settle_frames = 0;
  p.damping = 0;
  p.gravity = Vec3(0, -300, 0);
  p.contact_travel = contact_travel;
  const std::vector<Points3> frames(8, sphere.V);
  const auto out = sim::simulate_frames(g, sphere.F, frames, 30.0, p);
  double deepest = -1;
  for (const Points3& X : out) {
    REQUIRE(X.allFinite());
    for (int v = 0; v < X.rows(); ++v) deepest = std::max(deepest, r - X.row(v).norm());
  }
  return deepest;
}
}  // namespace

TEST_CASE("cloth: fast cloth makes its body contacts before it enters the body") {
  // The contact search reaches as far as each vertex travels until the next refresh, so the
  // sheet lands on the sphere. Tolerance 1 mm: the 64-segment sphere's chords lie up to 0.7 mm
  // inside the true one.
  const double reaching = deepest_in_sphere_after_fast_fall(1.0), fixed = deepest_in_sphere_after_fast_fall(0.0);
  MESSAGE("deepest inside the sphere: " << 1e3 * reaching << " mm reaching ahead, " << 1e3 * fixed
                                        << " mm with the fixed radius");
  CHECK(reaching < 0.001);
  CHECK(fixed > 0.02);  // the test can fail: with the fixed radius the sheet enters it unseen and stays
  sim::SimParams bad;
  bad.contact_travel = -1;
  CHECK_THROWS_AS(sim::ClothSolver(square_cloth(0.1, 0.05, 0.0), gdsr::Faces(0, 3), Points3(0, 3), bad), gdsr::Error);
}

namespace {
// A 30 mm garment simulated on `seconds` of a motion file from `start` seconds, put on the rest
// pose the garment catalogue says it is cut for; arm_clearance: gdsr::BodyOptions' (`data make`: 0.01 m).
struct GarmentRun {
  gdsr::BodySequence body;
  sim::Garment garment;
  std::vector<Points3> frames;
};
GarmentRun run_on_clip(const std::string& garment, const std::string& bvh, double start, double seconds,
                       const sim::SimParams& p = {}, double particle_distance = 0.03, double arm_clearance = 0) {
  REQUIRE_MESSAGE(std::ifstream(bvh).good(), bvh << " is missing (../shared beside the repository)");
  gdsr::BodyOptions opt;
  opt.arm_clearance = arm_clearance;
  opt.start_seconds = start;
  opt.max_seconds = seconds;
  opt.rest_arm_drop_degrees = sim::rest_arm_drop_degrees(garment);
  GarmentRun r{gdsr::load_body_sequence(bvh, opt), {}, {}};
  r.garment = sim::make_garment(garment, particle_distance, r.body.rest_mesh());
  r.frames = sim::simulate(r.garment, r.body, p);
  return r;
}

// Largest edge length over its length in the sewing pattern, in one frame of garment g.
double max_edge_stretch(const sim::Garment& g, const Points3& X) {
  REQUIRE(X.allFinite());
  double worst = 0;
  for (int f = 0; f < g.mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = g.mesh.F(f, k), j = g.mesh.F(f, (k + 1) % 3);
      const double rest = (g.mesh.UV.row(g.mesh.FUV(f, k)) - g.mesh.UV.row(g.mesh.FUV(f, (k + 1) % 3))).norm();
      worst = std::max(worst, (X.row(i) - X.row(j)).norm() / rest);
    }
  return worst;
}

// Largest edge length over its pattern length, over every frame of the 30 mm skirt on CMU
// salsa 61_02 from 3.5 s for 1.2 s (a hand sweeps past the pinned waistband at ~4.5 s).
double salsa_hand_sweep_stretch(const std::string& bvh, double release_stretch,
                                double substep_travel = sim::SimParams().substep_travel,
                                double bending_jacobi_max_ratio = sim::SimParams().bending_jacobi_max_ratio) {
  sim::SimParams p;
  p.contact_release_stretch = release_stretch;
  p.substep_travel = substep_travel;
  p.bending_jacobi_max_ratio = bending_jacobi_max_ratio;
  const GarmentRun run = run_on_clip("skirt_short", bvh, 3.5, 1.2, p);
  double worst = 0;
  for (const Points3& X : run.frames) worst = std::max(worst, max_edge_stretch(run.garment, X));
  return worst;
}
}  // namespace

TEST_CASE("cloth: a hand sweeping past the pinned waistband lets the cloth slip instead of dragging it out") {
  // On CMU salsa 61_02 a hand passing the pinned waistband carried single skirt vertices
  // 20+ cm out of the cloth: the contact, solved after the stretch, won every pass. With
  // contact_release_stretch (1.5) the contact gives way instead. Bound 2x: the stretch
  // solve's own overshoot within a substep. Without the release the hand drags edges past that
  // bound: over 3x with the skeleton's shoulders as filed, 2.2x with them moved out
  // (BodyOptions::min_shoulder_half_width), the hand passing farther from the waistband.
  const std::string bvh = std::string(GDSR_SHARED_DIR) + "/motions/cmu-salsa/61_02.bvh";
  REQUIRE_MESSAGE(std::ifstream(bvh).good(), bvh << " is missing (../shared beside the repository)");
  const double with = salsa_hand_sweep_stretch(bvh, 1.5);
  MESSAGE("largest edge stretch with release at 1.5: " << with);
  CHECK(with < 2.0);
  // The test can fail: without the release, at a fixed 20 substeps. (With adaptive substeps,
  // solver revision 32, the hand drags edges to 1.75x without the release: fewer substeps, as
  // at 10 mm or in a cheaper run, need the release.) With the bending factorised, as up to
  // revision 32: with Jacobi's last bits (revision 33) this draw drags them to 1.91x.
  const double without = salsa_hand_sweep_stretch(bvh, 1e9, 0, 0);
  MESSAGE("largest edge stretch without release, 20 substeps: " << without);
  CHECK(without > 2.0);
}

namespace {
// A 30 cm square sheet hanging in the plane z = 0, its top edge pinned to a "hanger" sphere, dressed
// on a "home" sphere 5 cm behind its middle (beyond the contact search), with a "hand" sphere 0.5 m
// to the side. One frame in which one of them (`moved`: 1 home, 2 hand) stands across the sheet's
// middle, its centre 25 mm in front of it, and the other where it was: the middle vertex is about
// 23 mm inside (deeper than max_push, within the contact search). Returns the body contacts found
// at the frame's start and the cloth after the frame.
constexpr double kSphereR = 0.05;  // m, the hanger, home and hand spheres of the hanging sheet
const Vec3 kHanger(0, 0.15 + kSphereR + 0.01, 0);

// The 30 cm sheet at 20 mm, in the plane z = 0 around the origin, its top edge pinned.
sim::Garment hanging_sheet() {
  sim::Garment g = square_cloth(0.3, 0.02, 0.0);
  for (int v = 0; v < g.mesh.V.rows(); ++v) {
    g.mesh.V.row(v) = Vec3(g.mesh.V(v, 0), g.mesh.V(v, 2), 0).transpose();
    if (g.mesh.V(v, 1) > 0.15 - 1e-9) g.pinned.push_back(v);
  }
  return g;
}

// `hand`: where the hand is in the first pose; `dressed_radius`: SimParams::dressed_radius.
std::pair<int, Points3> pierce_scene(int moved, bool limbs_pass_through, const Vec3& hand = Vec3(0.5, 0, 0),
                                     double dressed_radius = sim::SimParams().dressed_radius) {
  const double R = kSphereR;
  const sim::Garment g = hanging_sheet();
  const Vec3 hanger = kHanger, home(0, 0, -0.05 - R), across(0, 0, R - 0.025);
  auto body_with = [&](const Vec3& h, const Vec3& k) {
    return sim::merge_meshes(sim::merge_meshes(sim::make_sphere(hanger, R, 12, 24), sim::make_sphere(h, R, 12, 24)),
                             sim::make_sphere(k, R, 12, 24));
  };
  const auto rest = body_with(home, hand);
  const auto pose = moved == 1 ? body_with(across, hand) : body_with(home, across);
  sim::SimParams p;
  p.limbs_pass_through = limbs_pass_through;
  p.dressed_radius = dressed_radius;
  p.contact_every = p.substeps;  // one refresh, on the sheet as placed
  sim::ClothSolver solver(g, rest.F, rest.V, p);
  solver.step(pose.V, pose.V, 1.0 / 30);
  return {solver.num_body_contacts(), solver.positions()};
}
}  // namespace

TEST_CASE("cloth: only a part the cloth was not dressed on passes through it") {
  // The hand: the middle vertex and its edge neighbours (6 contacts here) make no contact with it,
  // so fewer contacts and a different frame than when the hand may push them.
  const auto [hand_on, x_hand_on] = pierce_scene(2, true);
  const auto [hand_off, x_hand_off] = pierce_scene(2, false);
  MESSAGE("hand across the sheet: " << hand_on << " body contacts, " << hand_off << " without the rule");
  CHECK(hand_on < hand_off);
  CHECK((x_hand_on - x_hand_off).cwiseAbs().maxCoeff() > 1e-4);
  // The part it was dressed on (the leg in a trouser leg): contacts kept, the same frame bit for bit.
  const auto [home_on, x_home_on] = pierce_scene(1, true);
  const auto [home_off, x_home_off] = pierce_scene(1, false);
  MESSAGE("home sphere across the sheet: " << home_on << " body contacts, " << home_off << " without the rule");
  CHECK(home_on == home_off);
  CHECK(x_home_on == x_home_off);
}

TEST_CASE("cloth: a part that other cloth was dressed on does not pass through the cloth") {
  // The thigh that a kneel closes onto the calf, the trouser in the crook (pants on CMU 131_01):
  // foreign to the cloth in the crook (dressed on the calf), but the trouser was dressed on it
  // too. Let through, the leg left the trouser leg and stayed out of it, 47-61 mm deep, to the
  // end of the clip. Here the "hand" starts 5 mm in front of the sheet's bottom edge, which is
  // dressed on it (under the garment: within dressed_radius of that cloth's closest points),
  // 16 cm below the middle vertex's home (foreign to it, pinch_separation 15 cm).
  const Vec3 under(0, -0.15, kSphereR + 0.005);
  const auto [on, x_on] = pierce_scene(2, true, under);
  const auto [off, x_off] = pierce_scene(2, false, under);
  MESSAGE("hand dressed on, across the sheet: " << on << " body contacts, " << off << " without limbs_pass_through");
  CHECK(on == off);
  CHECK(x_on == x_off);
  // At dressed_radius 0 (revision 28) it passes, as a hand the cloth was not dressed on does.
  const auto [old_on, x_old_on] = pierce_scene(2, true, under, 0.0);
  MESSAGE("... at dressed_radius 0: " << old_on << " body contacts");
  CHECK(old_on < off);  // the test can fail: the part passes
  CHECK((x_old_on - x_off).cwiseAbs().maxCoeff() > 1e-4);
  sim::SimParams bad;
  for (const double r : {-0.01, std::numeric_limits<double>::quiet_NaN()}) {
    bad.dressed_radius = r;
    CHECK_THROWS_AS(sim::ClothSolver(square_cloth(0.1, 0.05, 0.0), gdsr::Faces(0, 3), Points3(0, 3), bad), gdsr::Error);
  }
}

namespace {
// The sheet of pierce_scene, hanging from its hanger sphere, and a hand sphere that is put
// across its middle in one frame (the middle vertex 25 mm inside) and goes on through it, 15 mm
// per frame (0.45 m/s), to 20 cm behind it. Returns how far the hand carries the middle of the
// sheet along (-z), at most over the frames, metres.
double hand_through_sheet_carry(bool until_clear) {
  const sim::Garment g = hanging_sheet();
  int middle = 0;
  for (int v = 0; v < g.mesh.V.rows(); ++v)
    if (g.mesh.V.row(v).norm() < g.mesh.V.row(middle).norm()) middle = v;
  auto body_at = [&](const Vec3& hand) {
    return sim::merge_meshes(sim::make_sphere(kHanger, kSphereR, 12, 24), sim::make_sphere(hand, kSphereR, 12, 24));
  };
  std::vector<Vec3> path = {Vec3(0.5, 0, 0), Vec3(0, 0, 0.025)};
  while (path.back().z() > -0.2) path.push_back(path.back() - Vec3(0, 0, 0.015));
  for (int k = 0; k < 10; ++k) path.push_back(path.back());
  sim::SimParams p;
  p.limbs_pass_until_clear = until_clear;
  const auto rest = body_at(path[0]);
  sim::ClothSolver solver(g, rest.F, rest.V, p);
  double carried = 0;
  for (size_t t = 1; t < path.size(); ++t) {
    const auto prev = body_at(path[t == 1 ? 1 : t - 1]), now = body_at(path[t]);  // frame 1: the hand is put across
    solver.step(prev.V, now.V, 1.0 / 30);
    REQUIRE(solver.positions().allFinite());
    carried = std::max(carried, -solver.positions()(middle, 2));
  }
  return carried;
}
}  // namespace

TEST_CASE("cloth: a hand that went through the pinned cloth does not push it on while it is near") {
  // limbs_pass_until_clear: the cloth a hand went through, and the cloth around it, stays in
  // passing contact with the hand while the hand is within the contact search of it: pushed out
  // only where the hand's surface stands still or moves away, without friction. The first frame
  // kicks the sheet 30 mm back (the cloth just inside the hand's back is pushed out of it). Let
  // back into full contact once less than max_push inside, the cloth on the hand's far side was
  // pushed on ahead of it: that is how a hand that had gone through the first tier of the tiered
  // skirt on CMU 131_02 (30 mm) lifted it to the chest.
  const double with = hand_through_sheet_carry(true);
  MESSAGE("the hand carries the sheet's middle at most " << 1e3 * with << " mm");
  CHECK(with < 0.07);
  const double without = hand_through_sheet_carry(false);  // the test can fail: the hand carries the sheet
  MESSAGE("... in full contact again once out of the hand: " << 1e3 * without << " mm");
  CHECK(without > 0.1);
}

namespace {
// Frames with skirt cloth more than 5 mm inside the body in the last 20 of the 30 mm skirt on
// CMU 131_01 from 2 s for 2 s (76 frames with the rest blend): a swinging hand goes into the
// skirt at frame 20 and has passed it by frame 40.
int walking_hand_deep_frames_at_end(const std::string& bvh, bool limbs_pass_through, double self_crossed_push = 1) {
  sim::SimParams p;
  p.limbs_pass_through = limbs_pass_through;
  p.self_crossed_push = self_crossed_push;
  const GarmentRun run = run_on_clip("skirt_short", bvh, 2, 2, p);
  REQUIRE(run.frames.size() == 76);
  int deep = 0;
  for (size_t t = 0; t < run.frames.size(); ++t) {
    REQUIRE(run.frames[t].allFinite());
    if (t >= run.frames.size() - 20)
      deep += sim::body_penetration(run.frames[t], run.body.F, run.body.frames[t], 0.2).max_depth > 0.005;
  }
  return deep;
}
}  // namespace

TEST_CASE("cloth: a hand that went through the pinned skirt passes on instead of carrying it") {
  // The release above lets a hand through the skirt. Before limbs_pass_through the cloth it
  // went through stayed inside the hand: too deep to be pushed out (max_push), its ring pushed
  // onto the hand's surface and held there by friction, the skirt was carried, wrapped round the
  // wrist, to the end of the clip (cloth > 5 mm inside the body in frames 20-75; with the rule
  // 20-38, 53 and 54).
  const std::string bvh = std::string(GDSR_SHARED_DIR) + "/motions/cmu-walk/131_01.bvh";
  REQUIRE_MESSAGE(std::ifstream(bvh).good(), bvh << " is missing (../shared beside the repository)");
  const int with = walking_hand_deep_frames_at_end(bvh, true);
  MESSAGE("last 20 frames with cloth > 5 mm inside the body, limbs pass through: " << with);
  CHECK(with <= 2);
  // Since revision 20 the wrapped ring no longer forms on this clip without the rule either (0
  // frames): self-contact pushed crossed cloth back all the way then, and the control runs so.
  const int without = walking_hand_deep_frames_at_end(bvh, false, std::numeric_limits<double>::infinity());
  MESSAGE("... the hand carries the cloth (self-contact of revision 19): " << without);
  CHECK(without >= 15);  // the test can fail: the hand carries the skirt
}

namespace {
// Frames among the last 20 of the 30 mm pants on CMU 131_01 from 2 s for 2 s (76 frames with the
// rest blend) with cloth deeper than max_push (20 mm) inside the body: the walker kneels on the
// left knee from frame ~44 and gets up from frame ~56.
int kneel_lost_frames_at_end(const std::string& bvh, double dressed_radius,
                             double substep_travel = sim::SimParams().substep_travel,
                             double bending_jacobi_max_ratio = sim::SimParams().bending_jacobi_max_ratio) {
  sim::SimParams p;
  p.dressed_radius = dressed_radius;
  p.substep_travel = substep_travel;
  p.bending_jacobi_max_ratio = bending_jacobi_max_ratio;
  const GarmentRun run = run_on_clip("pants", bvh, 2, 2, p, 0.03, 0.01);  // the arms as `data make` turns them
  REQUIRE(run.frames.size() == 76);
  int lost = 0;
  for (size_t t = 0; t < run.frames.size(); ++t) {
    REQUIRE(run.frames[t].allFinite());
    if (t >= run.frames.size() - 20)
      lost += sim::body_penetration(run.frames[t], run.body.F, run.body.frames[t], 0.2).max_depth > p.max_push;
  }
  return lost;
}
}  // namespace

TEST_CASE("cloth: a kneel keeps the leg in its trouser leg") {
  // The thigh closes onto the calf with the trouser in the crook. Let through as a hand is
  // (limbs_pass_through: the thigh is foreign to the crook's cloth, dressed on the calf), the
  // leg left the trouser leg and the trouser stayed 30-60 mm inside it to the end of the clip.
  const std::string bvh = std::string(GDSR_SHARED_DIR) + "/motions/cmu-walk/131_01.bvh";
  const int with = kneel_lost_frames_at_end(bvh, sim::SimParams().dressed_radius);
  MESSAGE("last 20 frames with the trouser > 20 mm inside the leg: " << with);
  CHECK(with == 0);
  // The test can fail: the leg leaves the trouser, at a fixed 20 substeps (adaptive substeps,
  // solver revision 32, keep it in without the rule on this clip: 0 frames), with the bending
  // factorised, as up to revision 32 (with Jacobi's last bits, revision 33, this draw keeps it in: 0).
  const int without = kneel_lost_frames_at_end(bvh, 0.0, 0, 0);
  MESSAGE("... with every part foreign to the cloth passing (revision 28), 20 substeps: " << without);
  CHECK(without >= 15);
}

namespace {
// The hanging sheet, its pinned top edge 40 mm in front of a "hip" sphere (r = 0.1 m) it was
// dressed on, and a "hand" sphere (kSphereR) that comes from 0.35 m in front, 15 mm a frame, until
// its surface stands 20 mm behind the band, stays 10 frames and goes back (`back`: frames it then
// stays away); `outer_layer`: the sheet is the second layer of a layered garment. Measured on the true spheres, metres:
// the deepest the middle pin gets inside the hand, how far any pin is from its band position at the end, and
// how far any pin ever moves off its band other than towards its closest point on the hip (found by Embree).
struct PressedBand {
  double deepest_pin = -std::numeric_limits<double>::infinity(), pin_off_band = 0, pin_sideways = 0, pin_in = 0;
};
PressedBand hand_pressing_band(double pin_yield_rate, int back, bool outer_layer = false) {
  sim::Garment g = hanging_sheet();
  if (outer_layer) g.mesh.layer.assign(g.mesh.V.rows(), 1);
  const Vec3 hip(0, 0.15, -0.04 - 0.1);
  auto body_at = [&](double hand_z) {
    return sim::merge_meshes(sim::make_sphere(hip, 0.1, 24, 48),
                             sim::make_sphere(Vec3(0, 0.15, hand_z), kSphereR, 12, 24));
  };
  std::vector<double> path = {0.35};
  for (double z = 0.1; z > kSphereR - 0.02 + 1e-9; z -= 0.015) path.push_back(z);
  path.push_back(kSphereR - 0.02);
  for (int k = 0; k < 10; ++k) path.push_back(path.back());
  for (double z = path.back() + 0.015; z < 0.35; z += 0.015) path.push_back(z);
  for (int k = 0; k < back; ++k) path.push_back(0.35);
  int middle = g.pinned[0];
  for (int v : g.pinned)
    if (std::abs(g.mesh.V(v, 0)) < std::abs(g.mesh.V(middle, 0))) middle = v;
  sim::SimParams p;
  p.pin_yield_rate = pin_yield_rate;
  const auto rest = body_at(path[0]);
  const gdsr::ClosestPoints home = gdsr::BodyQuery(gdsr::TriMesh{rest.V, rest.F}).closest(g.mesh.V, false, 0.2);
  sim::ClothSolver solver(g, rest.F, rest.V, p);
  PressedBand out;
  for (size_t t = 1; t < path.size(); ++t) {
    solver.step(body_at(path[t - 1]).V, body_at(path[t]).V, 1.0 / 30);
    REQUIRE(solver.positions().allFinite());
    const Vec3 x = solver.positions().row(middle).transpose();
    out.deepest_pin = std::max(out.deepest_pin, kSphereR - (x - Vec3(0, 0.15, path[t])).norm());
    for (int v : g.pinned) {
      const Eigen::RowVector3d off = solver.positions().row(v) - g.mesh.V.row(v);
      const Eigen::RowVector3d in = (home.point.row(v) - g.mesh.V.row(v)).normalized();
      out.pin_sideways = std::max(out.pin_sideways, (off - off.dot(in) * in).norm());
      out.pin_in = std::max(out.pin_in, off.dot(in));
    }
  }
  for (int v : g.pinned)
    out.pin_off_band = std::max(out.pin_off_band, (solver.positions().row(v) - g.mesh.V.row(v)).norm());
  return out;
}
}  // namespace

TEST_CASE("cloth: a hand pressing a pinned band presses it in, and the band springs back") {
  // pin_yield_rate (5/s, the default since revision 24): a part the pin was not dressed on (the hand)
  // pushes it towards the part it was dressed on (the hip), as far as its stand-off from it (40 mm
  // here) allows. Rigid pins (revision 23's default) let the hand sink into a waistband standing off
  // the hip (skirt_pleated on salsa 61_03).
  // Tolerance 1 mm: the hand's 12-ring sphere's chords lie up to 0.5 mm inside the true sphere.
  REQUIRE(sim::SimParams{}.pin_yield_rate == 5);
  const PressedBand yielding = hand_pressing_band(5, 30);
  MESSAGE("yielding pins: the middle pin "
          << 1e3 * yielding.deepest_pin << " mm inside the hand at most (< 0: outside), " << 1e3 * yielding.pin_off_band
          << " mm off the band 1 s after");
  CHECK(yielding.deepest_pin < 0.001);
  // Back within 1 mm once the hand has gone: exp(-5/s x 1 s) of the ~24 mm press is 0.16 mm (the
  // release starts as the hand leaves, 0.6 s earlier: 0.005 mm measured).
  CHECK(yielding.pin_off_band < 0.001);
  // Pressed towards the hip only: the pins beside the middle one meet the hand's side at a slant,
  // and pushed along its normal they slid along the band, over the folds hanging from it.
  MESSAGE("pins pressed " << 1e3 * yielding.pin_in << " mm towards the hip, " << 1e3 * yielding.pin_sideways
                          << " mm any other way");
  CHECK(yielding.pin_in > 0.02);
  // Measured 1e-16 m; the tolerance leaves room for Embree's closest points to round unlike the solver's.
  CHECK(yielding.pin_sideways < 1e-5);
  const PressedBand rigid = hand_pressing_band(0, 0);  // the test can fail: rigid pins stay inside the hand
  MESSAGE("rigid pins: the middle pin " << 1e3 * rigid.deepest_pin << " mm inside the hand");
  CHECK(rigid.deepest_pin > 0.015);
  CHECK(rigid.pin_off_band < 1e-9);
  // A layered garment's pins stay rigid: pressed in, an outer layer's pins would go through the
  // pinned layers under them (skirt_tiered's three tiers share its waistband).
  const PressedBand outer = hand_pressing_band(5, 0, true);
  MESSAGE("an outer layer's pins: the middle pin " << 1e3 * outer.deepest_pin << " mm inside the hand");
  CHECK(outer.deepest_pin > 0.015);
  for (const double rate : {-1.0, std::nan("")}) {
    sim::SimParams bad;
    bad.pin_yield_rate = rate;
    CHECK_THROWS_AS(sim::ClothSolver(square_cloth(0.1, 0.05, 0.0), gdsr::Faces(0, 3), Points3(0, 3), bad), gdsr::Error);
  }
}

namespace {

// The 30 mm t-shirt on 1 s (from 2 s) of a CMU salsa clip, put on the A-pose it is cut for.
GarmentRun tshirt_on_salsa(const std::string& clip) {
  REQUIRE(sim::rest_arm_drop_degrees("tshirt") == 45);
  return run_on_clip("tshirt", std::string(GDSR_SHARED_DIR) + "/motions/cmu-salsa/" + clip + ".bvh", 2, 1);
}

}  // namespace

TEST_CASE("cloth: a garment without pins is carried by the arms it is worn on") {
  // The release above lets only cloth that hangs from a pin slip. Applied to a t-shirt (no
  // pins) it let the salsa dancer's rising arm pass through the sleeve: at 30 mm, 33 of 46
  // frames had cloth more than 5 mm inside the body, and at 10 mm the shirt fell to the feet.
  // Carried by the body, 3-7 frames of 46 did (revisions 7-14): a handful, where the hand
  // reaches the hip. Since revision 15 (max_push_step, below) the forearm no longer threads
  // the shirt (19 frames with an edge longer than 2x its pattern before, 0 now), but in
  // 29 frames a few vertices stay up to 18 mm inside a forearm that pressed into the shirt
  // across the body: at most 4 of 1,799 in a frame (the test allows 1%), not a sleeve the arm
  // went through. Revision 19's closer-fitting shirt: 22 frames, at most 10 of 1,523 vertices, 28 mm
  // deep; revision 26's, centred on the trunk: 19 frames, at most 9 of 1,493, 29 mm.
  const GarmentRun run = tshirt_on_salsa("61_02");
  const auto& body = run.body;
  const auto& out = run.frames;
  REQUIRE(run.garment.pinned.empty());
  int deep_frames = 0, most_deep = 0;
  double deepest = 0;
  for (size_t t = 0; t < out.size(); ++t) {
    REQUIRE(out[t].allFinite());
    const gdsr::BodyQuery query(gdsr::TriMesh{body.frames[t], body.F});
    const Eigen::VectorXd sd = query.closest(out[t], false, 0.2).sdist;
    const int deep = static_cast<int>((sd.array() < -0.005).count());
    deep_frames += deep > 0;
    most_deep = std::max(most_deep, deep);
    deepest = std::max(deepest, -sd.minCoeff());
  }
  MESSAGE("frames with cloth more than 5 mm inside the body: " << deep_frames << " of " << out.size() << "; at most "
                                                               << most_deep << " of " << out[0].rows()
                                                               << " vertices in a frame; deepest " << deepest << " m");
  CHECK(most_deep <= out[0].rows() / 100);
  CHECK(deepest < 0.04);
}

namespace {
// Frames of the 30 mm t-shirt on CMU 131_01 from 1.5 s for 1 s (46 frames with the rest blend)
// with an edge longer than twice its pattern length: cloth threaded on a forearm, stretched
// between its two sides. The arms drop from the A-pose onto the hips in the blend. (Pushed out
// at once, from 2 s: 28 frames until revision 26 centred the shirt on the trunk, 5 at 26, 11 at
// revision 27's self-contact detection, 9 since revision 28's shorter sleeves, 2 at revision 30,
// whose sleeves differ by a millimetre, hence the start of 1.5 s: 21; from 2.5 s 1, 131_02 from
// 2 s 0, 131_03 from 3 s 3.)
int tshirt_walk_torn_frames(double max_push_step, double substep_travel = sim::SimParams().substep_travel) {
  sim::SimParams p;
  p.max_push_step = max_push_step;
  p.substep_travel = substep_travel;
  const GarmentRun run =
      run_on_clip("tshirt", std::string(GDSR_SHARED_DIR) + "/motions/cmu-walk/131_01.bvh", 1.5, 1, p);
  REQUIRE(run.frames.size() == 46);
  int torn = 0;
  for (const Points3& X : run.frames) torn += max_edge_stretch(run.garment, X) > 2;
  return torn;
}
}  // namespace

TEST_CASE("cloth: a forearm dropping onto the hip does not thread the t-shirt") {
  // A forearm that overtook a hem vertex between two contact refreshes pushed it out in one go
  // through its far side: the cloth stayed threaded on the forearm, its edges stretched across
  // it. Moved at most max_push_step per contact pass beyond the body's motion, the vertex stays
  // on its side.
  const int capped = tshirt_walk_torn_frames(sim::SimParams{}.max_push_step);
  MESSAGE("frames with an edge > 2x its pattern, push capped at 5 mm per pass: " << capped << " of 46");
  CHECK(capped <= 2);
  // The test can fail: revision 14's push, at a fixed 20 substeps (with adaptive substeps,
  // solver revision 32, 1 frame: smaller steps overtake less).
  const int at_once = tshirt_walk_torn_frames(1e9, 0);
  MESSAGE("... pushed out at once, 20 substeps: " << at_once << " of 46");
  CHECK(at_once >= 5);
}

namespace {
// The sheet of pierce_scene (without gravity), dressed on its home sphere 5 cm behind its
// middle, and one frame in which home and hand spheres overlap across the middle: home's
// surface 15 mm in front of the sheet, the hand's 15 mm behind it, so the middle vertex lies
// inside both (within max_push of either). `pinned`: the sheet hangs from the hanger sphere as in
// pierce_scene; else it hangs from nothing, as a t-shirt. Returns the cloth after the frame.
Points3 overlap_pinch_scene(bool pinned, bool hold_unpinned_pinches) {
  const double R = kSphereR;
  sim::Garment g = hanging_sheet();
  if (!pinned) g.pinned.clear();
  auto body_with = [&](const Vec3& home, const Vec3& hand) {
    return sim::merge_meshes(sim::merge_meshes(sim::make_sphere(kHanger, R, 12, 24), sim::make_sphere(home, R, 12, 24)),
                             sim::make_sphere(hand, R, 12, 24));
  };
  const auto rest = body_with(Vec3(0, 0, -0.05 - R), Vec3(0.5, 0, 0));
  const auto pose = body_with(Vec3(0, 0, 0.015 - R), Vec3(0, 0, R - 0.015));
  sim::SimParams p;
  p.gravity = Vec3::Zero();
  p.hold_unpinned_pinches = hold_unpinned_pinches;
  sim::ClothSolver solver(g, rest.F, rest.V, p);
  solver.step(pose.V, pose.V, 1.0 / 30);
  REQUIRE(solver.positions().allFinite());
  return solver.positions();
}
}  // namespace

TEST_CASE("cloth: cloth without pins inside two body parts at once is held, not pushed onto either") {
  // An upper arm pressed into the chest (the capsule body crosses itself): pushed onto the
  // surface of the part it was dressed on, which lies inside the other, a t-shirt's sleeve and
  // side swapped sides in the armpit (the 10 mm t-shirt on salsa 60_02: 44% of frames free of
  // self-intersections, 100% held; revision 19).
  const sim::Garment g = hanging_sheet();
  int middle = 0;
  for (int v = 0; v < g.mesh.V.rows(); ++v)
    if (g.mesh.V.row(v).norm() < g.mesh.V.row(middle).norm()) middle = v;
  const double held = overlap_pinch_scene(false, true)(middle, 2);
  const double pushed = overlap_pinch_scene(false, false)(middle, 2);  // the test can fail: pushed onto home
  MESSAGE("the middle vertex's z after the frame: held " << held << " m, pushed onto its home sphere " << pushed
                                                         << " m");
  CHECK(std::abs(held) < 0.003);
  CHECK(pushed > 0.015);  // home's surface, 15 mm in front of the sheet, plus some of the thickness
  // Cloth that hangs from a pin is untouched by the rule, bit for bit.
  CHECK(overlap_pinch_scene(true, true) == overlap_pinch_scene(true, false));
}

namespace {
// Frames of the 30 mm t-shirt on CMU salsa 61_03 from 2 s for 0.7 s (37 frames with the rest
// blend; arms turned out of the trunk as `gdsr data make` does) with a cloth vertex more than
// 5 mm inside the body (Embree's exact signed distance, not the solver's contacts), and the
// deepest such vertex, for body contacts refreshed every `contact_every` substeps.
std::pair<int, double> tshirt_crook_deep_frames(int contact_every) {
  sim::SimParams p;
  p.contact_every = contact_every;
  const GarmentRun run =
      run_on_clip("tshirt", std::string(GDSR_SHARED_DIR) + "/motions/cmu-salsa/61_03.bvh", 2, 0.7, p, 0.03, 0.01);
  REQUIRE(run.frames.size() == 37);
  int deep = 0;
  double deepest = 0;
  for (size_t t = 0; t < run.frames.size(); ++t) {
    REQUIRE(run.frames[t].allFinite());
    const gdsr::BodyQuery query(gdsr::TriMesh{run.body.frames[t], run.body.F});
    const double d = -query.closest(run.frames[t], false, 0.2).sdist.minCoeff();
    deep += d > 0.005;
    deepest = std::max(deepest, d);
  }
  return {deep, deepest};
}
}  // namespace

TEST_CASE("cloth: a bending elbow's crook does not swallow the sleeve") {
  // From frame 16 the dancer's right elbow bends sharply. A body contact is a plane through the
  // closest body point, kept until the next refresh; in the closing crook the plane of one side
  // does not see the other side coming, and refreshed every 5th substep (the solver's default)
  // the sleeve ended up to 20 mm inside the arm, in 23 of 136 frames of the 4 s clip at 30 mm (14
  // at 10 mm). The t-shirt is simulated with a refresh every 3rd substep
  // (sim::body_contact_every): 2 frames (1 at 10 mm); every 2nd: 2 (at 30 mm). In this test's
  // 0.7 s, every 5th substep left 5 or more frames until revision 30 (sleeves cut to the wrist
  // found from the arm's sections); since then 3, 7.6 mm deep, against 0 and 1.8 mm.
  const int every = sim::body_contact_every("tshirt", sim::SimParams{}.contact_every);
  CHECK(every <= 3);
  CHECK(sim::body_contact_every("pants", sim::SimParams{}.contact_every) == sim::SimParams{}.contact_every);
  const auto [deep, deepest] = tshirt_crook_deep_frames(every);
  MESSAGE("frames with cloth > 5 mm inside the body: " << deep << " of 37, deepest " << 1e3 * deepest << " mm");
  CHECK(deep <= 2);
  CHECK(deepest < 0.01);
  const auto [stale, stale_deepest] = tshirt_crook_deep_frames(sim::SimParams{}.contact_every);  // can fail: 5
  MESSAGE("... refreshed every 5th substep: " << stale << " of 37, deepest " << 1e3 * stale_deepest << " mm");
  CHECK(stale >= deep + 3);
  CHECK(stale_deepest > 2 * deepest);
}

TEST_CASE("cloth: a t-shirt stays on a salsa dancer's shoulders and arms") {
  // Cut for a T-pose, the sleeves were too short over the top of the arm once the arms came
  // down, so they pulled the shoulders down off the body: on 60_02 (2-3 s, 30 mm) one sleeve
  // slid 30 cm down its arm, and in 36 of 46 frames a shoulder top was more than 5 cm from
  // the nearest cloth (26 with tapered sleeves alone; a one-off script with these
  // definitions). Cut for an A-pose with tapered sleeves: every forearm within 4-6 cm of its
  // sleeve, and 0-12 such frames over small changes of the setup (the arms reach forward and
  // pull the back of the loose shirt off the shoulder blades for a moment).
  const GarmentRun run = tshirt_on_salsa("60_02");
  const auto& body = run.body;
  const auto& out = run.frames;
  const gdsr::Points3& B0 = body.frames[0];
  const sim::BodyLandmarks lm = sim::measure_body(body.rest_mesh());
  // Body vertices followed through the motion: the top 2 cm of each shoulder (between neck
  // and shoulder joint).
  std::vector<int> shoulder;
  for (int v = 0; v < B0.rows(); ++v) {
    const double dx = std::abs(B0(v, 0) - lm.axis.x());
    if (dx > 0.10 && dx < 0.15 && B0(v, 1) > lm.shoulder_top_y - 0.02 && B0(v, 1) < lm.neck_y + 0.08)
      shoulder.push_back(v);
  }
  REQUIRE(shoulder.size() >= 6);
  // Each forearm under its cuff (body vertices within 4 cm of the arm's axis there; the sleeves
  // end 10 cm x height / 1.75 short of the wrist) and the cloth of its sleeve's outer half once
  // settled.
  std::vector<int> sleeve[2], forearm[2];
  for (int k = 0; k < 2; ++k) {
    const Vec3 w = lm.arm_root[k] + (lm.arm_len[k] - 0.10 * lm.height / 1.75) * lm.arm_dir[k];
    for (int v = 0; v < B0.rows(); ++v)
      if ((Vec3(B0.row(v)) - w).norm() < 0.04) forearm[k].push_back(v);
    for (int v = 0; v < out[0].rows(); ++v) {
      const Vec3 x = Vec3(out[0].row(v)) - lm.arm_root[k];
      const double t = x.dot(lm.arm_dir[k]);
      if (t > 0.5 * lm.arm_len[k] && (x - t * lm.arm_dir[k]).norm() < 0.12) sleeve[k].push_back(v);
    }
    REQUIRE(forearm[k].size() >= 4);
    REQUIRE(sleeve[k].size() >= 10);
  }
  auto mean = [](const gdsr::Points3& X, const std::vector<int>& idx) {
    Vec3 m = Vec3::Zero();
    for (int v : idx) m += Vec3(X.row(v));
    return Vec3(m / static_cast<double>(idx.size()));
  };
  double out_of_sleeve = 0;  // largest distance from a forearm's centre to its sleeve's nearest vertex
  int bare = 0;
  for (size_t t = 0; t < out.size(); ++t) {
    REQUIRE(out[t].allFinite());
    for (int k = 0; k < 2; ++k) {
      const Vec3 w = mean(body.frames[t], forearm[k]);
      double best = 1e9;
      for (int v : sleeve[k]) best = std::min(best, (Vec3(out[t].row(v)) - w).norm());
      out_of_sleeve = std::max(out_of_sleeve, best);
    }
    double gap = 0;
    for (int b : shoulder) {
      double best = 1e9;
      for (int v = 0; v < out[t].rows(); ++v) best = std::min(best, (out[t].row(v) - body.frames[t].row(b)).norm());
      gap = std::max(gap, best);
    }
    bare += gap > 0.05;
  }
  MESSAGE("farthest forearm from its sleeve: " << out_of_sleeve << " m; frames with a shoulder top > 5 cm from cloth: "
                                               << bare << " of " << out.size());
  CHECK(out_of_sleeve < 0.1);
  CHECK(bare <= 18);
}

TEST_CASE("cloth: simulation is deterministic run after run and across thread counts") {
  auto body = sim::make_mannequin(1.7);
  auto g = sim::make_garment("skirt_short", 0.04, body);
  sim::SimParams p;
  p.settle_frames = 2;
  std::vector<Points3> frames;
  for (int t = 0; t < 8; ++t) {
    Points3 V = body.V;
    V.col(0).array() += 0.03 * std::sin(t * 0.5);
    frames.push_back(V);
  }
  // Body contacts, the bending solve and the self-contact broad and narrow phases run in
  // parallel; each thread fills its own slots and the pairs are sorted, so 1 and 2 threads
  // must agree bit for bit.
  omp_set_num_threads(1);
  auto a = sim::simulate_frames(g, body.F, frames, 30.0, p);
  omp_set_num_threads(2);
  auto b = sim::simulate_frames(g, body.F, frames, 30.0, p);
  auto c = sim::simulate_frames(g, body.F, frames, 30.0, p);
  omp_set_num_threads(omp_get_num_procs());
  for (size_t t = 0; t < a.size(); ++t) {
    CHECK(a[t] == b[t]);
    CHECK(b[t] == c[t]);
  }
  CHECK((a.back() - a.front()).cwiseAbs().maxCoeff() > 1e-3);  // it moved: the comparison is not of rest states
}

TEST_CASE("cloth: a short skirt on a swaying, turning body stays bounded and pinned") {
  auto body = sim::make_mannequin(1.7);
  auto g = sim::make_garment("skirt_short", 0.03, body);
  REQUIRE(!g.pinned.empty());
  sim::SimParams p;
  p.settle_frames = 10;
  std::vector<Points3> frames;
  const int T = 45;
  for (int t = 0; t < T; ++t) {
    const double a = 0.4 * std::sin(2 * M_PI * t / 30.0);  // turn about y, 1 Hz
    const double dx = 0.08 * std::sin(2 * M_PI * t / 45.0);
    Eigen::Matrix3d R = Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix();
    Points3 V = (body.V * R.transpose());
    V.col(0).array() += dx;
    frames.push_back(V);
  }
  auto out = sim::simulate_frames(g, body.F, frames, 30.0, p);
  auto m = sim::sequence_metrics(g.mesh, out, body.F, frames, 30.0);
  double max_ke = 0, max_pen = 0, max_eu = 0, max_euv = 0;
  for (size_t t = 0; t < m.size(); ++t) {
    REQUIRE(out[t].allFinite());
    max_ke = std::max(max_ke, m[t].kinetic_energy);
    max_pen = std::max(max_pen, m[t].penetration.max_depth);
    max_eu = std::max({max_eu, m[t].strain.E_u, m[t].strain.E_v});
    max_euv = std::max(max_euv, m[t].strain.E_uv);
  }
  CAPTURE(max_ke);
  CAPTURE(max_pen);
  CAPTURE(max_eu);
  CAPTURE(max_euv);
  CHECK(max_ke < 1.0);  // joules; a 0.1 kg skirt at the body's speeds has ~0.01 J
  CHECK(max_pen < 0.01);
  CHECK(max_eu < 0.05);
  CHECK(max_euv < 0.1);
  // Pinned waistband vertices follow the body exactly (rigid motion of the binding).
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.4 * std::sin(2 * M_PI * (T - 1) / 30.0), Vec3::UnitY()).toRotationMatrix();
  const double dx = 0.08 * std::sin(2 * M_PI * (T - 1) / 45.0);
  for (int v : g.pinned) {
    const Vec3 expect = R * Vec3(out[0].row(v)) + Vec3(dx, 0, 0);
    CHECK((Vec3(out.back().row(v)) - expect).norm() < 1e-6);
  }
}

// With self-contact on (self-contact and the layer_gap constraint on layers lying flat on each
// other) and off (the layer_gap constraint alone), at the default compression and at
// compression_pd_exponent 1: there, before revision 16, the layer_gap constraint alone also
// paired layers across folds and wound the overskirt inside the underskirt (168 of 748 outer
// vertices inside after 10 frames, 308 after 30, 615 of 1262 at 30 mm).
TEST_CASE("cloth: layered skirt keeps the overskirt outside the underskirt") {
  auto body = sim::make_mannequin(1.7);
  auto g = sim::make_garment("skirt_layered", 0.04, body);
  REQUIRE(g.mesh.num_layers() == 2);
  const double k = sim::SimParams().compression_pd_exponent;
  for (const auto& [self_collision, exponent] : {std::pair<bool, double>{true, k}, {false, k}, {true, 1}, {false, 1}}) {
    CAPTURE(self_collision);
    CAPTURE(exponent);
    sim::SimParams p;
    p.settle_frames = 20;
    p.self_collision = self_collision;
    p.compression_pd_exponent = exponent;
    std::vector<Points3> frames(10, body.V);
    auto out = sim::simulate_frames(g, body.F, frames, 30.0, p);
    const auto& X = out.back();
    // For outer vertices at the height of the underskirt, radial distance from the axis must
    // not be smaller than the underskirt's at the same height and angle (binned).
    double under_min_y = 1e9;
    for (int v = 0; v < X.rows(); ++v)
      if (g.mesh.layer[v] == 0) under_min_y = std::min(under_min_y, X(v, 1));
    int bad = 0, total = 0;
    for (int v = 0; v < X.rows(); ++v) {
      if (g.mesh.layer[v] != 1 || X(v, 1) < under_min_y + 0.03) continue;
      const double ro = std::hypot(X(v, 0), X(v, 2));
      double ri = 0;
      for (int u = 0; u < X.rows(); ++u) {
        if (g.mesh.layer[u] != 0) continue;
        if (std::abs(X(u, 1) - X(v, 1)) < 0.02 &&
            std::abs(std::atan2(X(u, 0), X(u, 2)) - std::atan2(X(v, 0), X(v, 2))) < 0.05)
          ri = std::max(ri, std::hypot(X(u, 0), X(u, 2)));
      }
      ++total;
      if (ri > 0 && ro < ri - 0.005) ++bad;
    }
    CAPTURE(bad);
    CAPTURE(total);
    CHECK(total > 50);
    CHECK(bad < 0.02 * total);
  }
}

// Revision 9: with self-contact on, the layer_gap constraint pairs only layers lying flat on
// each other, outer outside inner; an outer layer found inside the inner one (as across a fold)
// is left to self-contact. Without self-contact such vertices are still paired (and pushed out).
TEST_CASE("cloth: with self-contact on, outer cloth found inside the inner layer is not paired") {
  auto body = sim::make_mannequin(1.7);
  auto g = sim::make_garment("skirt_layered", 0.04, body);
  sim::SimParams p;
  p.settle_frames = 10;
  const Points3 X = sim::simulate_frames(g, body.F, std::vector<Points3>(2, body.V), 30.0, p).back();
  double under_min_y = 1e9, top_y = -1e9;
  for (int v = 0; v < X.rows(); ++v) {
    if (g.mesh.layer[v] == 0) under_min_y = std::min(under_min_y, X(v, 1));
    top_y = std::max(top_y, X(v, 1));
  }
  // Each overskirt vertex where it covers the underskirt (3 cm above the underskirt's hem to
  // 5 cm below the waistband) put 1 cm inside its nearest underskirt vertex.
  Points3 inside = X;
  int moved = 0;
  for (int v = 0; v < X.rows(); ++v) {
    if (g.mesh.layer[v] != 1 || X(v, 1) < under_min_y + 0.03 || X(v, 1) > top_y - 0.05) continue;
    int u_best = -1;
    for (int u = 0; u < X.rows(); ++u)
      if (g.mesh.layer[u] == 0 &&
          (u_best < 0 || (X.row(u) - X.row(v)).squaredNorm() < (X.row(u_best) - X.row(v)).squaredNorm()))
        u_best = u;
    const Vec3 radial = Vec3(X(u_best, 0), 0, X(u_best, 2)).normalized();
    inside.row(v) = (Vec3(X.row(u_best)) - 0.01 * radial).transpose();
    ++moved;
  }
  auto pairs = [&](const Points3& start, bool self_collision) {
    sim::SimParams q = p;
    q.self_collision = self_collision;
    q.contact_every = q.substeps;  // layer pairs found once, on `start`
    sim::ClothSolver solver(g, body.F, body.V, q);
    solver.set_positions(start);
    solver.step(body.V, body.V, 1.0 / 30);
    return solver.num_layer_pairs();
  };
  const int flat = pairs(X, true), crossed = pairs(inside, true), crossed_no_self = pairs(inside, false);
  CAPTURE(moved);
  CAPTURE(flat);
  CAPTURE(crossed);
  CAPTURE(crossed_no_self);
  CHECK(flat > 50);
  CHECK(crossed_no_self >= moved);  // every moved vertex is paired (and would be pushed through)
  CHECK(crossed <= flat);           // with self-contact none of them is
}

TEST_CASE("cloth: bad inputs are rejected") {
  auto g = square_cloth(0.3, 0.05, 0.0);
  sim::SimParams p;
  p.substeps = 0;
  CHECK_THROWS_AS(sim::ClothSolver(g, gdsr::Faces(), Points3(), p), std::runtime_error);
  CHECK_THROWS_AS(sim::simulate_frames(g, gdsr::Faces(), {}, 30.0, sim::SimParams()), std::runtime_error);
  for (const double step : {0.0, -1.0, std::nan("")}) {
    sim::SimParams q;
    q.max_push_step = step;
    CHECK_THROWS_AS(sim::ClothSolver(g, gdsr::Faces(), Points3(), q), gdsr::Error);
  }
  for (const double push : {0.5, -1.0, std::nan("")}) {  // below one thickness it would limit every contact
    sim::SimParams q;
    q.self_crossed_push = push;
    CHECK_THROWS_AS(sim::ClothSolver(g, gdsr::Faces(), Points3(), q), gdsr::Error);
  }
  auto sphere = sim::make_sphere(Vec3(0, -1, 0), 0.2, 8, 16);
  std::vector<Points3> frames{sphere.V, Points3(sphere.V.topRows(5))};
  CHECK_THROWS_AS(sim::simulate_frames(g, sphere.F, frames, 30.0, sim::SimParams()), std::runtime_error);
}

TEST_CASE("cloth: resampling through UV reproduces a garment and its LR version") {
  auto body = sim::make_mannequin(1.7);
  auto lr = sim::make_garment("skirt_short", 0.04, body);
  auto hr = sim::make_garment("skirt_short", 0.02, body);
  // LR rest placement sampled at HR vertices lies on the same cone: close to the HR placement.
  const Points3 up = sim::resample_by_uv(lr.mesh, lr.mesh.V, hr.mesh);
  REQUIRE(up.rows() == hr.mesh.V.rows());
  const double err = (up - hr.mesh.V).rowwise().norm().maxCoeff();
  CAPTURE(err);
  CHECK(err < 0.01);  // chord error of 40 mm triangles on the cone
  // Sampling a garment from itself is exact.
  CHECK((sim::resample_by_uv(lr.mesh, lr.mesh.V, lr.mesh) - lr.mesh.V).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("cloth: short skirt on 1 s of CMU 01_01 stays bounded") {
  const std::string bvh = "/usr/share/assimp/models/BVH/01_01.bvh";
  REQUIRE_MESSAGE(std::ifstream(bvh).good(), bvh << " not installed (Debian's assimp-testmodels)");
  gdsr::BodyOptions opt;
  opt.max_seconds = 1.0;
  const auto body = gdsr::load_body_sequence(bvh, opt);
  const auto g = sim::make_garment("skirt_short", 0.03, body.rest_mesh());
  sim::SimParams p;
  const auto out = sim::simulate(g, body, p);
  REQUIRE(out.size() == body.frames.size());
  const auto m = sim::sequence_metrics(g.mesh, out, body.F, body.frames, body.fps);
  double max_ke = 0, max_pen = 0, mean_eu = 0, mean_euv = 0;
  for (size_t t = 0; t < m.size(); ++t) {
    REQUIRE(out[t].allFinite());
    max_ke = std::max(max_ke, m[t].kinetic_energy);
    max_pen = std::max(max_pen, m[t].penetration.max_depth);
    mean_eu += std::max(m[t].strain.E_u, m[t].strain.E_v) / m.size();
    mean_euv += m[t].strain.E_uv / m.size();
  }
  CAPTURE(max_ke);
  CAPTURE(max_pen);
  CAPTURE(mean_eu);
  CAPTURE(mean_euv);
  CHECK(max_ke < 1.0);    // joules (typical: ~0.03)
  CHECK(max_pen < 0.05);  // the hanging arm pinches the cloth against the hip: a few cm at most
  CHECK(mean_eu < 0.05);  // the paper's own roll-outs: 0.01-0.04
  CHECK(mean_euv < 0.1);
}

namespace {
// The short skirt settled on the static mannequin at particle distance h (frame 0 only).
struct SettledSkirt {
  sim::Garment g;
  Points3 X;
};
// compression_pd_ref <= 0 / exponent < 0: the solver's defaults (the ratio scaled by (ref / h)^2).
SettledSkirt settled_skirt(double h, double compression_ratio, double compression_pd_ref = 0, double exponent = -1) {
  const auto body = sim::make_mannequin(1.7);
  SettledSkirt s{sim::make_garment("skirt_short", h, body), Points3()};
  sim::SimParams p;
  p.compression_ratio = compression_ratio;
  if (compression_pd_ref > 0) p.compression_pd_ref = compression_pd_ref;
  if (exponent >= 0) p.compression_pd_exponent = exponent;
  s.X = sim::simulate_frames(s.g, body.F, {body.V}, 30.0, p).front();
  return s;
}
double mean_radius(const Points3& X) {
  return X.leftCols(1).binaryExpr(X.col(2), [](double x, double z) { return std::hypot(x, z); }).mean();
}
}  // namespace

TEST_CASE("cloth: the settle lets the placed skirt fall and the soft compression makes 30 and 15 mm hang alike") {
  // Settle: damped motion, not a velocity reset per frame (which lets the cloth fall only
  // ~5 mm per frame): the cone the skirt is placed as must have fallen in.
  const double ratio = sim::SimParams().compression_ratio;
  const SettledSkirt lr = settled_skirt(0.03, ratio), hr = settled_skirt(0.015, ratio);
  CHECK(mean_radius(hr.X) < mean_radius(hr.g.mesh.V) - 0.01);
  // Compression: a 30 mm mesh cannot form the 15 mm mesh's folds; with in-plane compression
  // as stiff as stretch it flares out instead (membrane locking). The soft compression,
  // scaled with the particle distance as the Euler buckling load is (0.011 at 30 mm, 0.044 at
  // 15 mm), hangs closest to the finer mesh; the same ratio at every distance lies between.
  const SettledSkirt stiff = settled_skirt(0.03, 1.0, 0.03), same = settled_skirt(0.03, 0.044, 0.03);
  auto gap = [&](const SettledSkirt& coarse) {
    return (sim::resample_by_uv(coarse.g.mesh, coarse.X, hr.g.mesh) - hr.X).rowwise().norm().mean();
  };
  const double soft_gap = gap(lr), same_gap = gap(same), stiff_gap = gap(stiff);
  MESSAGE("30 mm vs 15 mm at rest: mean distance " << 1e3 * soft_gap << " mm (scaled), " << 1e3 * same_gap
                                                   << " mm (the 15 mm ratio), " << 1e3 * stiff_gap << " mm (1)");
  CHECK(soft_gap < 0.85 * stiff_gap);  // 22.9 against 28.1 mm
  CHECK(soft_gap < same_gap);          // 22.9 against 25.2 mm (in motion the gain is larger: see SimParams)
  CHECK(same_gap < stiff_gap);
  CHECK(mean_radius(lr.X) < mean_radius(stiff.X));
  for (const auto* s : {&lr, &hr}) {
    const auto e = gdsr::strain_energies(s->g.mesh, s->X);
    CAPTURE(s->g.particle_distance);
    CHECK(e.E_u < 0.002);
    CHECK(e.E_v < 0.002);
    CHECK(e.E_uv < 0.01);
  }
}

TEST_CASE("cloth: compression softened as 1 / pd keeps 30 and 15 mm within 2x in strain, as 1 / pd^2 does not") {
  // The compression a mesh shows is how it takes up folds finer than itself. As 1 / pd^2 (the
  // default) the 30 mm skirt at rest compresses several times as much as the 15 mm one; as
  // 1 / pd, like it (SimParams::compression_pd_exponent), and it hangs a little farther from it.
  const double ratio = sim::SimParams().compression_ratio;
  REQUIRE(sim::SimParams().compression_pd_exponent == 2);
  auto compression = [](const SettledSkirt& k) {  // mean E_u + E_v
    const auto e = gdsr::strain_energies(k.g.mesh, k.X);
    return e.E_u + e.E_v;
  };
  auto gap = [](const SettledSkirt& coarse, const SettledSkirt& fine) {
    return (sim::resample_by_uv(coarse.g.mesh, coarse.X, fine.g.mesh) - fine.X).rowwise().norm().mean();
  };
  double c_ratio[2], gaps[2];
  for (int k = 1; k <= 2; ++k) {
    const SettledSkirt lr = settled_skirt(0.03, ratio, 0, k), hr = settled_skirt(0.015, ratio, 0, k);
    c_ratio[k - 1] = compression(lr) / compression(hr);
    gaps[k - 1] = gap(lr, hr);
    MESSAGE("exponent " << k << ": 30 mm E_u + E_v " << compression(lr) << ", 15 mm " << compression(hr) << " ("
                        << c_ratio[k - 1] << "x), mean distance " << 1e3 * gaps[k - 1] << " mm");
  }
  CHECK(c_ratio[0] < 2);     // 1.4x
  CHECK(c_ratio[1] > 2);     // 5.2x
  CHECK(gaps[1] < gaps[0]);  // 22.9 against 24.2 mm
}

TEST_CASE("cloth: the settle eases a placement that is not isometric to its pattern") {
  // The pants' crotch blends the leg tubes into the hip cylinder: placed edges are far from
  // their pattern lengths. At the pattern's rest lengths the first substeps snap them back at
  // metres per second; starting from the placement's lengths they stay near rest. On CMU
  // 01_01's body: the mannequin's leg capsules stand 2 cm apart up into the trunk, so the
  // pants' crotch seam between the legs would start 8 mm inside them.
  const std::string bvh = "/usr/share/assimp/models/BVH/01_01.bvh";
  REQUIRE_MESSAGE(std::ifstream(bvh).good(), bvh << " is missing (Debian's assimp-testmodels, see scripts/setup.sh)");
  const gdsr::TriMesh body = gdsr::load_body_rest(bvh);
  auto g = sim::make_garment("pants", 0.04, body);
  double worst = 1;  // placed / pattern edge length, furthest from 1
  for (int f = 0; f < g.mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const double l3 = (g.mesh.V.row(g.mesh.F(f, k)) - g.mesh.V.row(g.mesh.F(f, (k + 1) % 3))).norm();
      const double l2 = (g.mesh.UV.row(g.mesh.FUV(f, k)) - g.mesh.UV.row(g.mesh.FUV(f, (k + 1) % 3))).norm();
      if (std::abs(std::log(l3 / l2)) > std::abs(std::log(worst))) worst = l3 / l2;
    }
  CAPTURE(worst);
  REQUIRE(std::abs(std::log(worst)) > std::log(1.5));  // the case this guards: a non-isometric placement
  sim::SimParams p;
  p.self_collision = false;
  auto top_speed = [&](double blend) {
    sim::ClothSolver solver(g, body.F, body.V, p);
    solver.set_rest_blend(blend);
    solver.step(body.V, body.V, 1.0 / 30);
    return solver.velocities().rowwise().norm().maxCoeff();
  };
  const double eased = top_speed(0), snapped = top_speed(1);
  CAPTURE(eased);
  CAPTURE(snapped);
  CHECK(eased < 0.5);  // m/s: gravity alone gives 0.33 m/s after one frame
  CHECK(snapped > 2 * eased);
  CHECK_THROWS_AS(sim::ClothSolver(g, body.F, body.V, p).set_rest_blend(1.5), gdsr::Error);
}

TEST_CASE(
    "cloth: a finer settle started from the settled coarse skirt keeps its drape and relaxes to the fine fabric") {
  // A hanging skirt's folds are a buckling pattern: settled on their own, the 30 and 15 mm
  // skirts fold at different angles around the body. Started from the 30 mm drape, the 15 mm
  // settle keeps much of it (it still relaxes towards its own, finer folds: 13.8 against
  // 22.9 mm), and its strain relaxes to the fabric's.
  const auto body = sim::make_mannequin(1.7);
  const double ratio = sim::SimParams().compression_ratio;
  const SettledSkirt lr = settled_skirt(0.03, ratio), hr = settled_skirt(0.015, ratio);
  const Points3 start = sim::resample_by_uv(lr.g.mesh, lr.X, hr.g.mesh);
  const Points3 started = sim::simulate_frames(hr.g, body.F, {body.V}, 30.0, sim::SimParams(), {}, &start).front();
  const double own_gap = (hr.X - start).rowwise().norm().mean(),
               started_gap = (started - start).rowwise().norm().mean();
  MESSAGE("15 mm settle vs the 30 mm drape: mean distance " << 1e3 * own_gap << " mm settled alone, "
                                                            << 1e3 * started_gap << " mm started from it");
  CHECK(started_gap < 0.7 * own_gap);
  CHECK(started_gap > 1e-5);  // it did settle: the start is not returned as it was
  const auto e = gdsr::strain_energies(hr.g.mesh, started);
  CHECK(e.E_u < 0.002);
  CHECK(e.E_v < 0.002);
  CHECK(e.E_uv < 0.01);
  const Points3 wrong = Points3::Zero(start.rows() - 1, 3);
  CHECK_THROWS_AS(sim::simulate_frames(hr.g, body.F, {body.V}, 30.0, sim::SimParams(), {}, &wrong), gdsr::Error);
  Points3 nan = start;
  nan(0, 0) = NAN;
  CHECK_THROWS_AS(sim::simulate_frames(hr.g, body.F, {body.V}, 30.0, sim::SimParams(), {}, &nan), gdsr::Error);
}

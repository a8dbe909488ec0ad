#include <doctest/doctest.h>

#include "gdsr/body/body.hpp"
#include "gdsr/body/body_query.hpp"
#include "gdsr/error.hpp"
#include "gdsr/sim/body_landmarks.hpp"
#include "gdsr/sim/cloth_pins.hpp"
#include "gdsr/sim/garments.hpp"
#include "tests/support/cloth_bodies.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <string>

using gdsr::Points3;
using gdsr::Vec3;

namespace {

Points3 rows_of(const Points3& V, const std::vector<int>& ids) {
  Points3 out(ids.size(), 3);
  for (size_t k = 0; k < ids.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = V.row(ids[k]);
  return out;
}

// Edges of the garment whose two ends are both pinned.
std::vector<std::pair<int, int>> pinned_edges(const sim::Garment& g) {
  std::map<int, int> slot;
  for (size_t k = 0; k < g.pinned.size(); ++k) slot[g.pinned[k]] = static_cast<int>(k);
  std::vector<std::pair<int, int>> out;
  for (int f = 0; f < g.mesh.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int i = g.mesh.F(f, c), j = g.mesh.F(f, (c + 1) % 3);
      if (i < j && slot.count(i) && slot.count(j)) out.push_back({slot[i], slot[j]});
    }
  return out;
}

}  // namespace

TEST_CASE("pins: on the placement pose each pin is at its placement, and a rigid body motion carries them rigidly") {
  const gdsr::TriMesh body = sim::make_mannequin();
  const auto g = sim::make_garment("skirt_short", 0.04, body);
  REQUIRE(g.pinned.size() >= 8);
  const Points3 placed = rows_of(g.mesh.V, g.pinned);
  const sim::PinBinding pins(g.pinned, placed, g.mesh.F, body.F, body.V);
  REQUIRE(pins.size() == static_cast<int>(g.pinned.size()));
  CHECK(pins.num_bands() == 1);  // the waistband is one ring
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(0.3, 1, -0.2).normalized()).toRotationMatrix();
  const Vec3 t(0.4, -0.1, 2.0);
  Points3 moved = body.V;
  for (int v = 0; v < moved.rows(); ++v) moved.row(v) = (R * body.V.row(v).transpose() + t).transpose();
  double at_rest = 0, rigid = 0;
  for (int k = 0; k < pins.size(); ++k) {
    CHECK(pins.vertex(k) == g.pinned[k]);
    const Vec3 x = placed.row(k).transpose();
    at_rest = std::max(at_rest, (pins.position(k, body.V) - x).norm());
    rigid = std::max(rigid, (pins.position(k, moved) - (R * x + t)).norm());
  }
  CHECK(pins.support(0).size() >= 20);
  CHECK(at_rest < 1e-12);
  CHECK(rigid < 1e-12);
  // The band's frame (a pressed pin's offset turns with it): the identity at rest, R moved.
  Points3 x = g.mesh.V;
  std::vector<Eigen::Matrix3d> frames;
  pins.place(body.V, x, &frames);
  REQUIRE(frames.size() == 1);
  CHECK((frames[0] - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
  pins.place(moved, x, &frames);
  CHECK((frames[0] - R).cwiseAbs().maxCoeff() < 1e-12);
}

namespace {
// The 30 mm skirt on CMU salsa 60_03 from 2 s for 1 s: a hip turn with the pelvis tilting.
struct HipTurn {
  gdsr::BodySequence body;
  sim::Garment g;
};
HipTurn hip_turn() {
  const std::string bvh = std::string(GDSR_SHARED_DIR) + "/motions/cmu-salsa/60_03.bvh";
  REQUIRE_MESSAGE(std::ifstream(bvh).good(), bvh << " is missing");
  gdsr::BodyOptions opt;
  opt.start_seconds = 2;
  opt.max_seconds = 1;
  HipTurn h{gdsr::load_body_sequence(bvh, opt), {}};
  h.g = sim::make_garment("skirt_short", 0.03, h.body.rest_mesh());
  return h;
}
}  // namespace

TEST_CASE("pins: a waistband pinned off the body keeps its length through a salsa hip turn") {
  // The old binding (each pin on its closest triangle's frame, 4-5 cm out along the face
  // normal) stretched pinned waistband edges of the 10 mm skirt to 1.7x on this clip.
  // Measured on this 30 mm skirt: 2.0x with closest-triangle frames, 1.86x with a rigid fit
  // of the 6 cm of skin around each pin; a band moved as one keeps its edges to rounding.
  const HipTurn h = hip_turn();
  const auto& body = h.body;
  const auto& g = h.g;
  const Points3 placed = rows_of(g.mesh.V, g.pinned);
  const sim::PinBinding pins(g.pinned, placed, g.mesh.F, body.F, body.frames[0]);
  const auto edges = pinned_edges(g);
  REQUIRE(edges.size() >= 10);
  // The trunk under the band: body faces within 12 cm of a pin on the first pose (the arms,
  // which hang against the hips in this clip, are measured apart).
  gdsr::Faces trunk_F(0, 3);
  for (int f = 0; f < body.F.rows(); ++f) {
    bool near = false;
    for (int c = 0; c < 3 && !near; ++c)
      for (Eigen::Index k = 0; k < placed.rows() && !near; ++k)
        near = (body.frames[0].row(body.F(f, c)) - placed.row(k)).norm() < 0.12;
    if (near) trunk_F.conservativeResize(trunk_F.rows() + 1, 3), trunk_F.row(trunk_F.rows() - 1) = body.F.row(f);
  }
  REQUIRE(trunk_F.rows() > 100);
  double worst = 1, nearest = 1e9, farthest = 0, nearest_any = 1e9;
  Points3 x = g.mesh.V;
  gdsr::BodyQuery query(body.frame_mesh(0)), trunk(gdsr::TriMesh{body.frames[0], trunk_F});
  for (const Points3& pose : body.frames) {
    pins.place(pose, x);
    query.update(pose);
    trunk.update(pose);
    const auto hits = trunk.closest(rows_of(x, g.pinned));
    nearest = std::min(nearest, hits.sdist.minCoeff());
    farthest = std::max(farthest, hits.sdist.maxCoeff());
    nearest_any = std::min(nearest_any, query.closest(rows_of(x, g.pinned)).sdist.minCoeff());
    for (const auto& [i, j] : edges) {
      const double rest = (placed.row(i) - placed.row(j)).norm();
      const double now = (x.row(g.pinned[i]) - x.row(g.pinned[j])).norm();
      worst = std::max({worst, now / rest, rest / now});
    }
  }
  MESSAGE("largest pinned-edge length ratio over the clip: " << worst << "; pins " << nearest * 1e3 << " to "
                                                             << farthest * 1e3 << " mm outside the trunk, "
                                                             << nearest_any * 1e3 << " mm from any body part");
  CHECK(worst < 1 + 1e-9);
  // ... and rides on the trunk, never inside it, never left behind (the fitted band is 13-17 mm
  // off it through this clip on the body of solver revision 5, 8-17 mm on the column before; a
  // round band was 9-56 mm). A forearm hanging at the hip does reach 14 mm into the band: a
  // pinch, which the solver leaves to the part the cloth was dressed on.
  CHECK(nearest > 0.004);
  CHECK(farthest < 0.03);
}

TEST_CASE("pins: bad inputs are refused") {
  const gdsr::TriMesh body = sim::make_mannequin();
  const Points3 one = Points3::Zero(1, 3);
  const gdsr::Faces none(0, 3);
  CHECK_THROWS_AS(sim::PinBinding({0}, one, none, none, Points3(0, 3)), gdsr::Error);
  CHECK_THROWS_AS(sim::PinBinding({0, 1}, one, none, body.F, body.V), gdsr::Error);
  CHECK_THROWS_AS(sim::PinBinding({0}, one, none, body.F, body.V, 0.0), gdsr::Error);
  Points3 far = one;
  far(0, 1) = 100;
  CHECK_THROWS_AS(sim::PinBinding({0}, far, none, body.F, body.V), gdsr::Error);
}

TEST_CASE("pins: skirts' and pants' waistbands follow the waist section, not the circle through its widest point") {
  // Distances of the pinned waistband from the body, by an independent query (Embree). A round
  // waistband floated up to 56 mm off the belly and back of this body (10-56 mm); fitted, the
  // band keeps the design's ease (15 mm) all round, to the resolution of the body mesh.
  const std::string bvh = std::string(GDSR_SHARED_DIR) + "/motions/cmu-salsa/61_02.bvh";
  REQUIRE_MESSAGE(std::ifstream(bvh).good(), bvh << " is missing");
  gdsr::BodyOptions opt;
  opt.max_seconds = 0.01;
  const auto body = gdsr::load_body_sequence(bvh, opt);
  for (const char* name : {"skirt_short", "skirt_layered", "skirt_tiered", "skirt_pleated", "pants"}) {
    const auto g = sim::make_garment(name, 0.02, body.rest_mesh());
    gdsr::BodyQuery query(body.rest_mesh());
    const auto hits = query.closest(rows_of(g.mesh.V, g.pinned));
    // Innermost layer's band (the outer layers add their own ease on top).
    double lo = 1e9, hi = 0;
    for (size_t k = 0; k < g.pinned.size(); ++k) {
      if (!g.mesh.layer.empty() && g.mesh.layer[g.pinned[k]] != 0) continue;
      lo = std::min(lo, hits.sdist(static_cast<Eigen::Index>(k)));
      hi = std::max(hi, hits.sdist(static_cast<Eigen::Index>(k)));
    }
    MESSAGE(std::string(name) << ": waistband " << lo * 1e3 << " to " << hi * 1e3 << " mm off the body");
    CHECK(lo > 0.008);
    // The pleated waistband follows its pleats, whose outer folds stand ~35 mm further out.
    CHECK(hi < (std::string(name) == "skirt_pleated" ? 0.055 : 0.025));
    // The cone skirts' waistbands lie along the section at their pattern length (edges between
    // two pins, 3-D against flat length); drawn in radially they were gathered to 0.75x.
    if (std::string(name) == "skirt_pleated") continue;
    std::vector<char> pin(g.mesh.V.rows(), 0);
    for (int v : g.pinned) pin[v] = 1;
    double worst = 0;
    for (int f = 0; f < g.mesh.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = g.mesh.F(f, k), b = g.mesh.F(f, (k + 1) % 3);
        if (!pin[a] || !pin[b]) continue;
        const double flat = (g.mesh.UV.row(g.mesh.FUV(f, k)) - g.mesh.UV.row(g.mesh.FUV(f, (k + 1) % 3))).norm();
        worst = std::max(worst, std::abs((g.mesh.V.row(a) - g.mesh.V.row(b)).norm() / flat - 1));
      }
    MESSAGE(std::string(name) << ": waistband edges within " << worst * 100 << "% of their pattern length");
    CHECK(worst < 0.02);
  }
}

TEST_CASE("pins: the waist curve has the perimeter asked for and is laid out by arc length") {
  const auto lm = sim::measure_body(sim::make_mannequin(1.7));
  const double a = sim::waist_perimeter(lm, 0.015) / (2 * M_PI);
  const sim::WaistCurve c(lm, a);
  CHECK(c.ease() == doctest::Approx(0.015).epsilon(1e-6));
  // Equal steps of the fraction are equal steps of arc length (a fine polygon through it).
  const int n = 720;
  double total = 0, lo = 1e9, hi = 0;
  for (int i = 0; i < n; ++i) {
    auto at = [&](double f) {
      const double psi = c.psi_at(f), r = c.radius(psi);
      return Eigen::Vector2d(r * std::sin(psi), r * std::cos(psi));
    };
    const double step = (at((i + 1.0) / n) - at(static_cast<double>(i) / n)).norm();
    total += step;
    lo = std::min(lo, step);
    hi = std::max(hi, step);
  }
  CHECK(total == doctest::Approx(2 * M_PI * a).epsilon(1e-3));
  CHECK(hi / lo < 1.05);
  CHECK(c.psi_at(0) == doctest::Approx(0).epsilon(1e-12));
  CHECK(c.psi_at(1.25) == doctest::Approx(c.psi_at(0.25)).epsilon(1e-12));
  // A bare section longer than asked for: no ease (and no negative one).
  CHECK(sim::WaistCurve(lm, 0.01).ease() == 0);
}

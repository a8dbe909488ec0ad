#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/geometry/triangle.hpp"
#include "gdsr/geometry/wrinkles.hpp"
#include "gdsr/sim/cloth_solver.hpp"
#include "gdsr/sim/cloth_tracking.hpp"
#include "tests/support/cloth_bodies.hpp"
#include "tests/support/square_cloth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

using gdsr::Points3;
using gdsr::Vec3;

namespace {

using gdsr_test::square_cloth;

// Mean distance from each point of X to the closest point of the surface (V, F), brute force
// over triangles: a yardstick that does not use the correspondence the tracker pulls along.
double mean_distance_to_surface(const Points3& X, const Points3& V, const gdsr::Faces& F) {
  double sum = 0;
  for (int i = 0; i < X.rows(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    const Vec3 p = X.row(i).transpose();
    for (int f = 0; f < F.rows(); ++f) {
      const auto c = gdsr::closest_point_on_triangle(p, V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(),
                                                     V.row(F(f, 2)).transpose());
      best = std::min(best, (c.point - p).squaredNorm());
    }
    sum += std::sqrt(best);
  }
  return sum / static_cast<double>(X.rows());
}

// Largest |row| of X - Y.
double max_row_norm(const Points3& X, const Points3& Y) { return (X - Y).rowwise().norm().maxCoeff(); }

}  // namespace

TEST_CASE("cloth tracking: the pull moves what the LR mesh can hold by beta and leaves fine wrinkles alone") {
  const sim::Garment lr = square_cloth(0.6, 0.03, 0), hr = square_cloth(0.6, 0.01, 0);
  const gdsr::Correspondence c = gdsr::compute_correspondence(lr.mesh, hr.mesh);
  const sim::GuideTracker tracker(c);
  const Points3 g = lr.mesh.V, target = gdsr::upsample(c, g);
  const std::vector<double> winv(static_cast<size_t>(hr.mesh.V.rows()), 1.0);
  // A flat sheet: the upsampled LR is the HR rest shape (linear interpolation is exact on a plane).
  REQUIRE(max_row_norm(target, hr.mesh.V) < 1e-12);

  // A rigid offset is what the LR mesh can represent: it shrinks by exactly beta, and a
  // uniform guide velocity is taken up by the same fraction.
  const Vec3 offset(0.01, -0.02, 0.005), guide_speed(0.3, 0, -0.1);
  Points3 x = target.rowwise() + offset.transpose(), v = Points3::Zero(x.rows(), 3);
  const Points3 gv = Points3::Zero(g.rows(), 3).rowwise() + guide_speed.transpose();
  tracker.pull(g, gv, 0.25, winv, x, v);
  CHECK(max_row_norm(x, target.rowwise() + 0.75 * offset.transpose()) < 1e-12);
  CHECK(max_row_norm(v, Points3::Zero(v.rows(), 3).rowwise() + 0.25 * guide_speed.transpose()) < 1e-12);

  // Pinned vertices (winv 0) never move.
  std::vector<double> pinned = winv;
  pinned[0] = 0;
  Points3 xp = target.rowwise() + offset.transpose(), vp = Points3::Zero(xp.rows(), 3);
  tracker.pull(g, gv, 0.25, pinned, xp, vp);
  CHECK(max_row_norm(xp.topRows(1), target.topRows(1).rowwise() + offset.transpose()) == 0);

  // Normal waves on the sheet: the hat-weighted mean over an LR vertex's support (30 mm each
  // way) keeps nearly all of a wave much longer than that and little of one near it (in 1-D
  // the triangle filter keeps sinc^2(pi * 30 mm / wavelength): 0.98 at 400 mm, 0.09 at 40 mm;
  // this 2-D mesh keeps 0.99 and 0.24). rms of D (x - U g) over LR vertices against the wave's.
  auto kept = [&](double wavelength) {
    Points3 w = target;
    for (int i = 0; i < w.rows(); ++i) w(i, 1) += 0.004 * std::cos(2 * M_PI * w(i, 0) / wavelength);
    const Points3 r = tracker.lr_residual(g, w);
    Points3 ref = g;
    for (int j = 0; j < ref.rows(); ++j) ref(j, 1) = 0.004 * std::cos(2 * M_PI * g(j, 0) / wavelength);
    return std::sqrt(r.col(1).squaredNorm() / ref.col(1).squaredNorm());
  };
  const double smooth = kept(0.4), fine = kept(0.04);
  MESSAGE("kept of a 400 mm wave: " << smooth << ", of a 40 mm wave: " << fine);
  CHECK(smooth > 0.9);
  CHECK(fine < 0.3);
}

TEST_CASE("cloth tracking: cloth that went through itself, and three rings of edges around it, is not pulled") {
  const sim::Garment lr = square_cloth(0.6, 0.03, 0), hr = square_cloth(0.6, 0.01, 0);
  const gdsr::Correspondence c = gdsr::compute_correspondence(lr.mesh, hr.mesh);
  const sim::GuideTracker tracker(c);
  const gdsr::Faces& F = hr.mesh.F;
  const int n = static_cast<int>(hr.mesh.V.rows());
  int centre = 0;
  hr.mesh.V.rowwise().norm().minCoeff(&centre);
  std::vector<char> tangled(static_cast<size_t>(n), 0);
  tangled[static_cast<size_t>(centre)] = 1;
  const std::vector<double> winv(static_cast<size_t>(n), 1.0);
  const std::vector<double> w = sim::untangled_pull_weights(winv, tangled, F, 3);

  // Yardstick: edge hops from the tangled vertex by breadth-first search over ring-1 neighbours.
  const gdsr::Csr nb = gdsr::vertex_neighbours(F, n);
  std::vector<int> hops(static_cast<size_t>(n), -1), queue{centre};
  hops[static_cast<size_t>(centre)] = 0;
  for (size_t q = 0; q < queue.size(); ++q)
    for (int k = nb.offsets[queue[q]]; k < nb.offsets[queue[q] + 1]; ++k) {
      const int j = nb.items[static_cast<size_t>(k)];
      if (hops[static_cast<size_t>(j)] < 0) {
        hops[static_cast<size_t>(j)] = hops[static_cast<size_t>(queue[q])] + 1;
        queue.push_back(j);
      }
    }
  int held = 0, wrong = 0;
  for (int i = 0; i < n; ++i) {
    const bool near = hops[static_cast<size_t>(i)] >= 0 && hops[static_cast<size_t>(i)] <= 3;
    held += near;
    wrong += w[static_cast<size_t>(i)] != (near ? 0.0 : 1.0);
  }
  MESSAGE(held << " of " << n << " vertices held");
  CHECK(held >= 19);  // at least the vertex and its first ring on a mesh of mostly six neighbours
  CHECK(wrong == 0);

  // Pulled by a rigid offset, the held vertices stay and the others move by beta of it.
  const Points3 target = gdsr::upsample(c, lr.mesh.V);
  const Vec3 offset(0.01, -0.02, 0.005);
  Points3 x = target.rowwise() + offset.transpose(), v = Points3::Zero(n, 3);
  const Points3 x0 = x;
  tracker.pull(lr.mesh.V, Points3::Zero(lr.mesh.V.rows(), 3), 0.25, w, x, v);
  double held_moved = 0, free_error = 0;
  for (int i = 0; i < n; ++i) {
    const double moved = (x.row(i) - x0.row(i)).norm();
    if (w[static_cast<size_t>(i)] == 0)
      held_moved = std::max(held_moved, moved);
    else
      free_error = std::max(free_error, std::abs(moved - 0.25 * offset.norm()));
  }
  CHECK(held_moved == 0);
  CHECK(free_error < 1e-12);

  // No tangle: the weights are winv itself; flags of the wrong length are refused.
  CHECK(sim::untangled_pull_weights(winv, std::vector<char>(static_cast<size_t>(n), 0), F, 3) == winv);
  CHECK_THROWS_AS(sim::untangled_pull_weights(winv, std::vector<char>(3, 0), F, 3), gdsr::Error);
}

TEST_CASE("cloth tracking: a tracked HR drape follows the LR one and keeps finer folds") {
  // A 0.7 m square dropped on a sphere (r 0.2 m) for 1 s at 30 and 10 mm. Independent, the
  // folds around the rim buckle where each mesh's own noise puts them; tracked at the solver's
  // default rate (SimParams::track_rate), the HR sheet lies on the LR one at the LR scale and
  // still folds more finely. The distance to the LR surface cannot fall to zero: the finer
  // folds themselves stand off it (measured here: 6.1 mm independent, 2.0 mm tracked at 30/s,
  // 4.1 mm at 10/s; curvature 1.33x, 1.17x and 1.20x the upsampled LR's).
  const double r = 0.2;
  const auto sphere = sim::make_sphere(Vec3(0, 0, 0), r, 32, 64);
  const sim::Garment lr = square_cloth(0.7, 0.03, r + 0.03), hr = square_cloth(0.7, 0.01, r + 0.03);
  sim::SimParams p;
  p.settle_frames = 0;
  p.damping = 2.0;
  p.track_rate = 0;
  const std::vector<Points3> body(30, sphere.V);
  const auto lr_frames = sim::simulate_frames(lr, sphere.F, body, 30.0, p);
  const gdsr::Correspondence c = gdsr::compute_correspondence(lr.mesh, hr.mesh);
  const sim::GuideTracker tracker(c);
  const sim::Guide guide{tracker, lr_frames};

  const auto independent = sim::simulate_frames(hr, sphere.F, body, 30.0, p);
  sim::SimParams pt = p;
  pt.track_rate = sim::SimParams().track_rate;
  REQUIRE(pt.track_rate > 0);
  const auto tracked = sim::simulate_frames(hr, sphere.F, body, 30.0, pt, {}, nullptr, &guide);
  REQUIRE(tracked.back().allFinite());
  const Points3& L = lr_frames.back();
  const double d_independent = mean_distance_to_surface(independent.back(), L, lr.mesh.F);
  const double d_tracked = mean_distance_to_surface(tracked.back(), L, lr.mesh.F);
  const double k_lr = gdsr::wrinkle_measure(gdsr::upsample(c, L), hr.mesh.F).mean_curvature;
  const double k_tracked = gdsr::wrinkle_measure(tracked.back(), hr.mesh.F).mean_curvature;
  const double k_independent = gdsr::wrinkle_measure(independent.back(), hr.mesh.F).mean_curvature;
  MESSAGE("mean distance from the HR vertices to the LR surface: independent " << 1e3 * d_independent << " mm, tracked "
                                                                               << 1e3 * d_tracked << " mm");
  MESSAGE("mean |mean curvature|, 1/m: LR upsampled " << k_lr << ", HR independent " << k_independent << ", HR tracked "
                                                      << k_tracked);
  CHECK(d_tracked < 0.75 * d_independent);
  CHECK(k_tracked > 1.1 * k_lr);

  // Rate 0 with a guide is the independent simulation, bit for bit.
  const std::vector<Points3> few(4, sphere.V);
  const std::vector<Points3> few_guide(lr_frames.begin(), lr_frames.begin() + 4);
  const sim::Guide short_guide{tracker, few_guide};
  CHECK(sim::simulate_frames(hr, sphere.F, few, 30.0, p, {}, nullptr, &short_guide).back() ==
        sim::simulate_frames(hr, sphere.F, few, 30.0, p).back());
  // A guide of the wrong length is refused.
  const sim::Guide wrong{tracker, few_guide};
  CHECK_THROWS_AS(sim::simulate_frames(hr, sphere.F, body, 30.0, pt, {}, nullptr, &wrong), std::runtime_error);
}

// The body's closest-point grid (gdsr/sim/cloth_collision.hpp) against a brute-force search
// over every face: the grid only prunes (cells, then face boxes), so it must give the same
// face, point, normal and signed distance, bit for bit, for any pose between the two it was
// built for, with and without a face filter, in one step or two (candidates, then closest).
#include <doctest/doctest.h>

#include "gdsr/geometry/triangle.hpp"
#include "gdsr/sim/cloth_collision.hpp"
#include "tests/support/cloth_bodies.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <random>

using gdsr::Points3;
using gdsr::Vec3;

namespace {

// Every face in ascending order, with the grid's rule: a face wins when it is closer by more
// than 1e-14 m^2, and faces tied within that (a shared edge or vertex) average their normals.
sim::SurfaceHit brute_force(const Vec3& x, const gdsr::Faces& F, const Points3& V, double radius,
                            const std::function<bool(int)>& accept) {
  sim::SurfaceHit hit;
  double best = radius * radius;
  Vec3 nsum = Vec3::Zero();
  for (int f = 0; f < F.rows(); ++f) {
    if (accept && !accept(f)) continue;
    const Vec3 p0 = V.row(F(f, 0)), p1 = V.row(F(f, 1)), p2 = V.row(F(f, 2));
    const Vec3 bc = gdsr::closest_point_on_triangle(x, p0, p1, p2).bary;
    const Vec3 q = bc.x() * p0 + bc.y() * p1 + bc.z() * p2;
    const double d2 = (x - q).squaredNorm();
    const Vec3 n = (p1 - p0).cross(p2 - p0).normalized();
    if (d2 < best - 1e-14) {
      best = d2, hit.face = f, hit.bary = bc, hit.point = q, nsum = n;
    } else if (hit.face >= 0 && d2 <= best + 1e-14) {
      nsum += n;
    }
  }
  if (hit.face < 0) return hit;
  hit.normal = nsum.norm() > 0 ? Vec3(nsum.normalized()) : Vec3(0, 1, 0);
  const double d = std::sqrt(best);
  hit.signed_distance = (x - hit.point).dot(hit.normal) >= 0 ? d : -d;
  return hit;
}

}  // namespace

TEST_CASE("cloth collision: the body grid finds the same closest point as every face, bit for bit") {
  // A mannequin moving 6 cm sideways and 3 cm up over the frame; queries at the middle of the
  // motion, near the surface (inside and outside it, and on its vertices, where faces tie),
  // with the solver's search radius and a filter that rejects every third face.
  const gdsr::TriMesh body = sim::make_mannequin(1.7);
  Points3 V1 = body.V;
  V1.col(0).array() += 0.06;
  V1.col(1).array() += 0.03;
  const Points3 Vmid = 0.5 * (body.V + V1);
  sim::SurfaceGrid grid;
  grid.build(body.F, body.V, V1, 0.05);
  const double radius = 0.034;
  const std::function<bool(int)> every_third = [](int f) { return f % 3 != 0; };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  int found = 0, inside = 0, ties = 0;
  for (int k = 0; k < 3000; ++k) {
    Vec3 x;
    if (k % 10 == 0) {  // on a vertex: every face around it ties at distance 0
      x = Vmid.row(static_cast<int>(u(rng) * (Vmid.rows() - 1))).transpose();
    } else {  // near the surface: a random vertex moved by up to 4 cm
      const Vec3 v = Vmid.row(static_cast<int>(u(rng) * (Vmid.rows() - 1))).transpose();
      x = v + 0.04 * Vec3(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1);
    }
    // One candidate set for both queries, asked in turn (as the solver does) and again in the
    // other order: its faces' closest points, computed by the first query that needs them, serve
    // the next one.
    sim::SurfaceCandidates shared, reversed;
    grid.candidates(x, Vmid, radius, shared);
    grid.candidates(x, Vmid, radius, reversed);
    const sim::SurfaceHit reversed_third = grid.closest(reversed, Vmid, every_third);
    for (const auto* accept : {static_cast<const std::function<bool(int)>*>(nullptr), &every_third}) {
      const std::function<bool(int)> filter = accept ? *accept : std::function<bool(int)>();
      const sim::SurfaceHit g = grid.closest(x, Vmid, radius, filter);
      const sim::SurfaceHit b = brute_force(x, body.F, Vmid, radius, filter);
      const sim::SurfaceHit s = grid.closest(shared, Vmid, filter);
      const sim::SurfaceHit r = accept ? reversed_third : grid.closest(reversed, Vmid, filter);
      REQUIRE(g.face == b.face);
      for (const sim::SurfaceHit* two_step : {&s, &r}) {
        REQUIRE(two_step->face == b.face);
        if (b.face < 0) continue;
        CHECK(two_step->point == b.point);
        CHECK(two_step->normal == b.normal);
        CHECK(two_step->signed_distance == b.signed_distance);
      }
      if (b.face < 0) continue;
      CHECK(g.point == b.point);
      CHECK(g.bary == b.bary);
      CHECK(g.normal == b.normal);
      CHECK(g.signed_distance == b.signed_distance);
      found += !accept;
      inside += !accept && b.signed_distance < 0;
      ties += !accept && k % 10 == 0;
    }
  }
  MESSAGE(found << " of 3000 queries within reach, " << inside << " inside, " << ties << " on vertices");
  CHECK(found > 1000);  // the comparison covers hits, misses, points inside and ties
  CHECK(inside > 50);
  CHECK(ties > 200);
}

TEST_CASE("cloth collision: the body grid at the edges of its cells, far away, with NaN, and beside a second grid") {
  // Queries whose search box reaches past the block of cells that hold faces (above the head,
  // below the feet, beside the arms), points far outside it, and a grid of another body queried
  // in between on the same thread (the candidate set is kept per thread): all as the brute
  // force finds them.
  const gdsr::TriMesh body = sim::make_mannequin(1.7);
  const gdsr::TriMesh small = sim::make_mannequin(0.9);
  sim::SurfaceGrid grid, other;
  grid.build(body.F, body.V, body.V, 0.05);
  other.build(small.F, small.V, small.V, 0.05);
  const Vec3 lo = body.V.colwise().minCoeff().transpose(), hi = body.V.colwise().maxCoeff().transpose();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  int found = 0;
  for (int k = 0; k < 600; ++k) {
    Vec3 x;
    for (int c = 0; c < 3; ++c) x[c] = lo[c] + (hi[c] - lo[c]) * u(rng);
    const int c = k % 3;
    x[c] = (k / 3) % 2 ? hi[c] + 0.03 * u(rng) : lo[c] - 0.03 * u(rng);  // within the radius of the box's face
    const sim::SurfaceHit g = grid.closest(x, body.V, 0.034);
    const sim::SurfaceHit b = brute_force(x, body.F, body.V, 0.034, {});
    REQUIRE(g.face == b.face);
    if (b.face >= 0) {
      CHECK(g.point == b.point);
      CHECK(g.normal == b.normal);
      ++found;
    }
    const sim::SurfaceHit s = other.closest(x, small.V, 0.034);
    CHECK(s.face == brute_force(x, small.F, small.V, 0.034, {}).face);
  }
  MESSAGE(found << " of 600 queries at the block's faces within reach");
  CHECK(found > 20);
  CHECK(grid.closest(Vec3(100, 0, 0), body.V, 0.034).face == -1);
  CHECK(grid.closest(Vec3(-1e12, 1e12, 0), body.V, 0.034).face == -1);
  CHECK(grid.closest(Vec3(std::nan(""), 1, 0), body.V, 0.034).face == -1);
  sim::SurfaceGrid none;
  none.build(gdsr::Faces(0, 3), body.V, body.V, 0.05);
  CHECK(none.empty());
  CHECK(none.closest(Vec3::Zero(), body.V, 1).face == -1);
  // Two poses kilometres apart would need a block of billions of cells: refused in one line.
  Points3 far = body.V;
  far.col(0).array() += 5000;
  CHECK_THROWS_WITH_AS(grid.build(body.F, body.V, far, 0.05), doctest::Contains("too many grid cells"),
                       std::runtime_error);
}

// Closest point on a triangle (gdsr/geometry/triangle.hpp) against dense sampling of the
// triangle and the closed-form answers of each Voronoi region.
#include <doctest/doctest.h>

#include "gdsr/geometry/triangle.hpp"

#include <random>

using gdsr::TriangleRegion;
using gdsr::Vec3;

TEST_CASE("triangle: closest point is never farther than any sampled point of the triangle") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a(U(rng), U(rng), U(rng)), b(U(rng), U(rng), U(rng)), c(U(rng), U(rng), U(rng)),
        p(2 * U(rng), 2 * U(rng), 2 * U(rng));
    const gdsr::TriangleClosest t = gdsr::closest_point_on_triangle(p, a, b, c);
    CHECK(t.bary.sum() == doctest::Approx(1).epsilon(1e-12));
    CHECK(t.bary.minCoeff() >= -1e-12);
    CHECK((t.bary.x() * a + t.bary.y() * b + t.bary.z() * c - t.point).norm() < 1e-12);
    const double d = (t.point - p).norm();
    double best = 1e300;
    const int n = 60;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const double u = double(i) / n, v = double(j) / n;
        best = std::min(best, ((1 - u - v) * a + u * b + v * c - p).norm());
      }
    CHECK(d <= best + 1e-12);
    CHECK(d >= best - 0.05);  // the sampling step bounds how far the samples can be off
  }
}

TEST_CASE("triangle: regions of the unit right triangle in closed form") {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  auto q = [&](double x, double y, double z) { return gdsr::closest_point_on_triangle(Vec3(x, y, z), a, b, c); };
  CHECK(q(0.2, 0.3, 0.7).region == TriangleRegion::Face);
  CHECK((q(0.2, 0.3, 0.7).point - Vec3(0.2, 0.3, 0)).norm() < 1e-15);
  CHECK(q(-1, -1, 0).region == TriangleRegion::VertexA);
  CHECK(q(2, -0.5, 0).region == TriangleRegion::VertexB);
  CHECK(q(-0.5, 2, 1).region == TriangleRegion::VertexC);
  const gdsr::TriangleClosest ab = q(0.4, -1, 0);
  CHECK(ab.region == TriangleRegion::EdgeAB);
  CHECK((ab.bary - Vec3(0.6, 0.4, 0)).norm() < 1e-15);
  CHECK(q(-1, 0.25, 0).region == TriangleRegion::EdgeCA);
  const gdsr::TriangleClosest bc = q(1, 1, 0);
  CHECK(bc.region == TriangleRegion::EdgeBC);
  CHECK((bc.point - Vec3(0.5, 0.5, 0)).norm() < 1e-15);
}

TEST_CASE("triangle: a degenerate triangle gives a finite answer on it") {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(2, 0, 0);  // collinear
  for (const Vec3& p : {Vec3(0.5, 1, 0), Vec3(1.5, -1, 2), Vec3(-1, 0, 0), Vec3(3, 0, 0)}) {
    const gdsr::TriangleClosest t = gdsr::closest_point_on_triangle(p, a, b, c);
    CHECK(t.point.allFinite());
    CHECK(t.point.y() == 0);
    CHECK(t.point.z() == 0);
    CHECK(t.point.x() >= 0);
    CHECK(t.point.x() <= 2);
  }
  const gdsr::TriangleClosest z = gdsr::closest_point_on_triangle(Vec3(1, 1, 1), a, a, a);
  CHECK(z.point == a);
}

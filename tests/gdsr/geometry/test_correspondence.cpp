#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/geometry/uv_raster.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace gdsr;

namespace {

double max_abs(const Points3& a, const Points3& b) { return (a - b).cwiseAbs().maxCoeff(); }

Points3 random_positions(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd;
  Points3 P(n, 3);
  for (int i = 0; i < P.size(); ++i) P.data()[i] = nd(rng);
  return P;
}

// LR grid and its midpoint subdivision as HR: upsample must reproduce the HR rest shape
// exactly, and downsample(upsample(x)) == x for any LR positions x.
void check_subdivided(const GarmentMesh& lr) {
  const GarmentMesh hr = subdivide_midpoint(lr);
  const Correspondence c = compute_correspondence(lr, hr);
  validate_correspondence(c);
  CHECK(max_abs(upsample(c, lr.V), hr.V) < 1e-12);
  const Points3 x = random_positions(static_cast<int>(lr.V.rows()), 7);
  const Points3 up = upsample(c, x);
  CHECK(max_abs(up.topRows(lr.V.rows()), x) < 1e-12);  // LR vertices are HR vertices
  CHECK(max_abs(downsample(c, up), x) < 1e-12);
  // Edge midpoints are the averages of their endpoints for arbitrary LR positions.
  const GarmentMesh hx = subdivide_midpoint(GarmentMesh{x, lr.F, lr.UV, lr.FUV, lr.uv_to_vertex, {}});
  CHECK(max_abs(up, hx.V) < 1e-12);
  for (int i = 0; i < hr.V.rows(); ++i) {
    REQUIRE(c.hr_nearest_lr[i] >= 0);
    if (i < lr.V.rows()) CHECK(c.hr_nearest_lr[i] == i);
  }
}

}  // namespace

TEST_CASE("correspondence: exact on a planar subdivided panel") {
  check_subdivided(gdsr_test::grid_garment(gdsr_test::GridSpec(6, 4, 0.6, 0.4)));
}

TEST_CASE("correspondence: exact on a curved patch and a seamed tube") {
  check_subdivided(gdsr_test::grid_garment(gdsr_test::GridSpec(8, 5, 0.8, 0.5).bent(1.5)));  // bent patch
  check_subdivided(gdsr_test::grid_garment(gdsr_test::GridSpec(8, 3, 0.9, 0.3).tube()));     // tube with a UV seam

  // HR midpoints pushed radially onto the cylinder (a "true" curved HR mesh): the upsample
  // stays on the LR triangles, so it differs from the HR surface by exactly the sagitta.
  const double w = 0.8, bend = 1.5, R = w / bend;
  const GarmentMesh lr = gdsr_test::grid_garment(gdsr_test::GridSpec(8, 5, w, 0.5).bent(bend));
  GarmentMesh hr = subdivide_midpoint(lr);
  double max_sagitta = 0;
  for (int i = 0; i < hr.V.rows(); ++i) {
    Eigen::Vector2d radial(hr.V(i, 0), hr.V(i, 2) - R);  // the cylinder axis is at x = 0, z = R
    const double r = radial.norm();
    radial *= R / r;
    hr.V(i, 0) = radial.x();
    hr.V(i, 2) = radial.y() + R;
    max_sagitta = std::max(max_sagitta, R - r);
  }
  CHECK(max_sagitta > 1e-4);  // the curvature is visible at this resolution
  const Correspondence c = compute_correspondence(lr, hr);
  const Points3 up = upsample(c, lr.V);
  for (int i = 0; i < hr.V.rows(); ++i) {
    const Eigen::Vector2d radial(up(i, 0), up(i, 2) - R);
    CHECK(std::abs(up(i, 1) - hr.V(i, 1)) < 1e-12);
    CHECK((Eigen::Vector3d(up.row(i)) - Eigen::Vector3d(hr.V.row(i))).norm() ==
          doctest::Approx(R - radial.norm()).epsilon(1e-9).scale(1e-3));
  }
}

TEST_CASE("correspondence: a finer unrelated grid reproduces affine fields") {
  // LR 30 mm-like and HR 10 mm-like grids of the same panel, not nested: an affine function
  // of UV is interpolated exactly by any barycentric map.
  const GarmentMesh lr = gdsr_test::grid_garment(gdsr_test::GridSpec(7, 5, 0.7, 0.5));
  const GarmentMesh hr = gdsr_test::grid_garment(gdsr_test::GridSpec(20, 16, 0.7, 0.5));
  const Correspondence c = compute_correspondence(lr, hr);
  auto affine = [](const GarmentMesh& g) {
    Points3 P(g.V.rows(), 3);
    for (int i = 0; i < P.rows(); ++i) {
      const double u = g.V(i, 0), v = g.V(i, 1);
      P.row(i) << 2 * u - v + 0.3, 0.5 * u + 3 * v, -u + 0.1;
    }
    return P;
  };
  CHECK(max_abs(upsample(c, affine(lr)), affine(hr)) < 1e-12);
  CHECK(max_abs(downsample(c, affine(hr)), affine(lr)) < 1e-12);
  CHECK(max_abs(at_lr_scale(c, affine(hr)), affine(hr)) < 1e-12);  // the LR mesh holds an affine shape
  Points3 ripple = affine(hr);  // plus the finest ripple the HR grid holds (+-1 cm from column to column): not held
  for (int i = 0; i < ripple.rows(); ++i) ripple(i, 2) += 0.01 * std::cos(M_PI * hr.V(i, 0) / (0.7 / 20));
  CHECK(max_abs(at_lr_scale(c, ripple), ripple) > 1e-3);
  for (int i = 0; i < hr.V.rows(); ++i) {
    const Eigen::Vector2d p = hr.UV.row(i);
    double best = std::numeric_limits<double>::infinity();
    for (int j = 0; j < lr.UV.rows(); ++j) best = std::min(best, (Eigen::Vector2d(lr.UV.row(j)) - p).norm());
    CHECK((Eigen::Vector2d(lr.UV.row(c.hr_nearest_lr[i])) - p).norm() == doctest::Approx(best).epsilon(1e-12));
  }
  CHECK_THROWS_AS(upsample(c, affine(hr)), std::runtime_error);
}

TEST_CASE("correspondence: locator agrees with brute force, outside points clamp") {
  // Two panels with a gap between them (like a sewing pattern), random queries inside,
  // on edges, in the gap and far outside.
  GarmentMesh a = gdsr_test::grid_garment(gdsr_test::GridSpec(5, 4, 0.5, 0.4));
  GarmentMesh b = gdsr_test::grid_garment(gdsr_test::GridSpec(3, 6, 0.3, 0.6));
  Points2 UV(a.UV.rows() + b.UV.rows(), 2);
  UV << a.UV, (b.UV.rowwise() + Eigen::RowVector2d(0.7, 0.1));
  Faces F(a.FUV.rows() + b.FUV.rows(), 3);
  F << a.FUV, (b.FUV.array() + static_cast<int>(a.UV.rows())).matrix();
  const UVLocator loc(UV, F);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ud(-0.5, 1.5);
  for (int q = 0; q < 2000; ++q) {
    Eigen::Vector2d p(ud(rng), ud(rng));
    if (q % 10 == 0) p = UV.row(q % UV.rows()).transpose();  // exactly on a vertex
    if (q % 10 == 1) p = 0.5 * (UV.row(F(q % F.rows(), 0)) + UV.row(F(q % F.rows(), 1))).transpose();  // on an edge
    double best = std::numeric_limits<double>::infinity();
    for (int f = 0; f < F.rows(); ++f)
      best = std::min(best, closest_on_triangle(p, UV.row(F(f, 0)), UV.row(F(f, 1)), UV.row(F(f, 2))).distance);
    const UVHit h = loc.locate(p);
    REQUIRE(h.tri >= 0);
    CHECK(h.distance == doctest::Approx(best).epsilon(1e-12));
    CHECK(h.bary.minCoeff() >= 0.0);
    CHECK(h.bary.sum() == doctest::Approx(1.0).epsilon(1e-12));
    // The barycentric point is the closest point: its distance to p is the reported distance.
    const Eigen::Vector2d c = h.bary(0) * UV.row(F(h.tri, 0)).transpose() +
                              h.bary(1) * UV.row(F(h.tri, 1)).transpose() + h.bary(2) * UV.row(F(h.tri, 2)).transpose();
    CHECK((c - p).norm() == doctest::Approx(h.distance).epsilon(1e-9).scale(1.0));
    if (best == 0) CHECK((c - p).norm() < 1e-12);
  }
  // A point far to the left clamps onto the left edge of panel a.
  const UVHit far = loc.locate(Eigen::Vector2d(-3.0, 0.2));
  CHECK(far.distance == doctest::Approx(3.0));
}

TEST_CASE("correspondence: UV raster pixels reproduce their centres") {
  const GarmentMesh hr = gdsr_test::grid_garment(gdsr_test::GridSpec(12, 8, 0.6, 0.4).tube());
  const UVRaster r = rasterize_uv(hr.UV, hr.FUV, 256, 256, 4);
  CHECK(r.tri.size() == 256u * 256u);
  // Uniform scale: the long side fills width - 2 * padding pixels.
  CHECK(r.scale == doctest::Approx(248 / 0.6));
  int inside = 0;
  for (int j = 0; j < r.height; ++j)
    for (int i = 0; i < r.width; ++i) {
      const size_t px = static_cast<size_t>(j) * r.width + i;
      const Eigen::Vector2d uv = r.pixel_center_uv(i, j);
      const bool in_layout = uv.x() > 1e-9 && uv.x() < 0.6 - 1e-9 && uv.y() > 1e-9 && uv.y() < 0.4 - 1e-9;
      const bool out_layout = uv.x() < -1e-9 || uv.x() > 0.6 + 1e-9 || uv.y() < -1e-9 || uv.y() > 0.4 + 1e-9;
      if (in_layout) CHECK(r.tri[px] >= 0);
      if (out_layout) CHECK(r.tri[px] == -1);
      if (r.tri[px] < 0) continue;
      ++inside;
      const int f = r.tri[px];
      const Eigen::Vector3d w(r.bary[px * 3], r.bary[px * 3 + 1], r.bary[px * 3 + 2]);
      CHECK(w.sum() == doctest::Approx(1.0).epsilon(1e-6));
      CHECK(w.minCoeff() >= 0.0);
      const Eigen::Vector2d back = w(0) * hr.UV.row(hr.FUV(f, 0)).transpose() +
                                   w(1) * hr.UV.row(hr.FUV(f, 1)).transpose() +
                                   w(2) * hr.UV.row(hr.FUV(f, 2)).transpose();
      CHECK((back - uv).norm() < 1e-6);
      const Eigen::Vector2d pix = r.uv_to_pixel(uv);
      CHECK(std::abs(pix.x() - (i + 0.5)) < 1e-9);
      CHECK(std::abs(pix.y() - (j + 0.5)) < 1e-9);
    }
  // Covered pixel count matches the layout area in pixels (within one pixel row/column).
  const double expect = 0.6 * 0.4 * r.scale * r.scale;
  CHECK(std::abs(inside - expect) < (0.6 + 0.4) * r.scale * 2 + 4);
  CHECK_THROWS_AS(rasterize_uv(Points2(0, 2), Faces(0, 3)), std::runtime_error);
}

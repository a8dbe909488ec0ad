#include <doctest/doctest.h>

#include "tests/support/cloth_bodies.hpp"
#include "gdsr/sim/garments.hpp"
#include "gdsr/sim/sim_metrics.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <set>

using gdsr::Vec2;
using gdsr::Vec3;

namespace {

double uv_area(const gdsr::GarmentMesh& m) {
  double a = 0;
  for (int f = 0; f < m.FUV.rows(); ++f) {
    const Vec2 p0 = m.UV.row(m.FUV(f, 0)), p1 = m.UV.row(m.FUV(f, 1)), p2 = m.UV.row(m.FUV(f, 2));
    a += 0.5 * ((p1 - p0).x() * (p2 - p0).y() - (p1 - p0).y() * (p2 - p0).x());
  }
  return a;
}

}  // namespace

TEST_CASE("garments: the catalogue's garments build, fit around the body and face outwards") {
  const auto body = sim::make_mannequin(1.7);
  const auto lm = sim::measure_body(body);
  CHECK(lm.waist_r == doctest::Approx(0.15 * 1.7 / 1.62).epsilon(0.05));
  const auto names = sim::garment_names();
  REQUIRE(names.size() >= 5);
  for (const auto& name : names) {
    CAPTURE(name);
    if (name == "tshirt") {  // sleeves need arms: tested on a skeleton body (test_garments_paper.cpp)
      CHECK_THROWS_AS(sim::make_garment(name, 0.03, body), std::runtime_error);
      continue;
    }
    const auto g = sim::make_garment(name, 0.03, body);
    const auto& m = g.mesh;
    CHECK(g.name == name);
    CHECK(m.V.rows() > 200);
    CHECK(m.V.allFinite());
    CHECK(m.UV.rows() > m.V.rows());  // seams weld at least some UV copies
    for (int u = 0; u < m.UV.rows(); ++u) REQUIRE(m.uv_to_vertex[u] < m.V.rows());
    // Rest placement is close to the flat pattern (developable cones, near-isometric tubes).
    const auto se = gdsr::strain_energies(m, m.V);
    // Shorts: the crotch point is pulled between the legs, so the placement is looser there.
    const double tol = name == "shorts" || name == "pants" ? 0.15 : 0.05;
    CHECK(se.E_u < tol);
    CHECK(se.E_v < tol);
    CHECK(se.E_uv < tol);
    // Outward normals: area-weighted normals point away from the body axis on average.
    double out = 0, total = 0;
    for (int f = 0; f < m.F.rows(); ++f) {
      const Vec3 a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
      const Vec3 n = (b - a).cross(c - a);
      Vec3 radial = (a + b + c) / 3 - lm.axis;
      radial.y() = 0;
      out += n.dot(radial.normalized());
      total += n.norm();
    }
    CHECK(out > 0.5 * total);
    // No part of the rest placement is deep inside the body (the mannequin has no
    // shoulders, so the top's shoulder straps are not checked).
    if (name != "top") CHECK(sim::body_penetration(m.V, body.F, body.V).max_depth < 0.01);
    const bool skirt = name.rfind("skirt", 0) == 0;
    if (skirt || name == "shorts" || name == "pants") CHECK(!g.pinned.empty());
    const int layers = name == "skirt_layered" || name == "dress_layered" ? 2 : name == "skirt_tiered" ? 3 : 1;
    CHECK(m.num_layers() == layers);
  }
  CHECK_THROWS_AS(sim::make_garment("cape", 0.03, body), std::runtime_error);
}

TEST_CASE("garments: LR and HR share the pattern outline and scale in vertex count") {
  const auto body = sim::make_mannequin(1.7);
  for (const std::string name : {"skirt_short", "top"}) {
    CAPTURE(name);
    const auto lr = sim::make_garment(name, 0.03, body);
    const auto hr = sim::make_garment(name, 0.015, body);
    CHECK(uv_area(lr.mesh) == doctest::Approx(uv_area(hr.mesh)).epsilon(1e-9));
    const Vec2 lo_l = lr.mesh.UV.colwise().minCoeff(), hi_l = lr.mesh.UV.colwise().maxCoeff();
    const Vec2 lo_h = hr.mesh.UV.colwise().minCoeff(), hi_h = hr.mesh.UV.colwise().maxCoeff();
    CHECK((lo_l - lo_h).norm() < 1e-12);
    CHECK((hi_l - hi_h).norm() < 1e-12);
    const double ratio = static_cast<double>(hr.mesh.V.rows()) / lr.mesh.V.rows();
    CHECK(ratio > 3.0);
    CHECK(ratio < 5.0);
  }
}

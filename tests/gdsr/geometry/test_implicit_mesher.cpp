// The implicit-surface mesher (gdsr/geometry/implicit_mesher.hpp) on a sphere and on two
// merged spheres: closed, manifold, outward, on the surface, with the right volume.
#include <doctest/doctest.h>

#include "gdsr/geometry/implicit_mesher.hpp"

#include <cmath>
#include <map>
#include <utility>

namespace {

// Every undirected edge in exactly two faces, opposite directions: closed and manifold.
bool closed_manifold(const gdsr::Faces& F) {
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++directed[{F(f, k), F(f, (k + 1) % 3)}];
  for (const auto& [e, n] : directed)
    if (n != 1 || directed.count({e.second, e.first}) != 1) return false;
  return true;
}

double volume(const gdsr::TriMesh& m) {
  double v = 0;
  for (int f = 0; f < m.F.rows(); ++f)
    v += gdsr::Vec3(m.V.row(m.F(f, 0))).dot(gdsr::Vec3(m.V.row(m.F(f, 1))).cross(gdsr::Vec3(m.V.row(m.F(f, 2)))));
  return v / 6;
}

}  // namespace

TEST_CASE("implicit mesher: a sphere of radius 0.1 m is closed, outward, on the surface, 4/3 pi r^3") {
  const double r = 0.1;
  auto sphere = [r](const gdsr::Vec3& p) { return p.norm() - r; };
  const gdsr::TriMesh m = gdsr::mesh_implicit(sphere, gdsr::Vec3::Constant(-r), gdsr::Vec3::Constant(r), 0.01, 0.015);
  CHECK(m.F.rows() > 100);
  CHECK(closed_manifold(m.F));
  for (int i = 0; i < m.V.rows(); ++i) CHECK(std::abs(m.V.row(i).norm() - r) < 1e-6);
  // Inscribed polyhedron: a little under the sphere's volume.
  const double exact = 4.0 / 3.0 * M_PI * r * r * r;
  CHECK(volume(m) > 0.97 * exact);
  CHECK(volume(m) < exact);
  // Deterministic.
  const gdsr::TriMesh m2 = gdsr::mesh_implicit(sphere, gdsr::Vec3::Constant(-r), gdsr::Vec3::Constant(r), 0.01, 0.015);
  CHECK(m2.V == m.V);
  CHECK(m2.F == m.F);
}

TEST_CASE("implicit mesher: two overlapping spheres make one closed surface / no surface throws") {
  auto two = [](const gdsr::Vec3& p) {
    return std::min((p - gdsr::Vec3(-0.05, 0, 0)).norm() - 0.08, (p - gdsr::Vec3(0.05, 0, 0)).norm() - 0.08);
  };
  const gdsr::TriMesh m =
      gdsr::mesh_implicit(two, gdsr::Vec3(-0.13, -0.08, -0.08), gdsr::Vec3(0.13, 0.08, 0.08), 0.01, 0.015);
  CHECK(closed_manifold(m.F));
  CHECK(volume(m) > 0);
  auto empty = [](const gdsr::Vec3&) { return 1.0; };
  CHECK_THROWS_WITH(gdsr::mesh_implicit(empty, gdsr::Vec3::Zero(), gdsr::Vec3::Ones(), 0.2, 0.2),
                    doctest::Contains("implicit_mesher: marching tetrahedra found no surface"));
}

#include "tests/support/cloth_bodies.hpp"

#include <array>
#include <cmath>
#include <utility>
#include <vector>
#include <stdexcept>

namespace sim {

using gdsr::Vec3;

namespace {
constexpr double kPi = 3.14159265358979323846;

// Surface of revolution around the y axis: profile (radius, y) for t in [0, 1] from the
// bottom pole to the top pole; poles are single vertices.
template <class Profile> gdsr::TriMesh revolve(const Profile& prof, double x, double z, int rings, int segments) {
  if (rings < 2 || segments < 3) throw std::runtime_error("sim/cloth_bodies: too few rings or segments");
  gdsr::TriMesh m;
  const int nv = 2 + (rings - 1) * segments;
  m.V.resize(nv, 3);
  auto [r0, y0] = prof(0.0);
  auto [r1, y1] = prof(1.0);
  (void)r0;
  (void)r1;
  m.V.row(0) = Vec3(x, y0, z).transpose();
  m.V.row(nv - 1) = Vec3(x, y1, z).transpose();
  for (int i = 1; i < rings; ++i) {
    auto [r, y] = prof(static_cast<double>(i) / rings);
    for (int j = 0; j < segments; ++j) {
      const double a = 2 * kPi * j / segments;
      m.V.row(1 + (i - 1) * segments + j) = Vec3(x + r * std::sin(a), y, z + r * std::cos(a)).transpose();
    }
  }
  std::vector<std::array<int, 3>> f;
  auto id = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) f.push_back({0, id(1, j + 1), id(1, j)});
  for (int i = 1; i < rings - 1; ++i)
    for (int j = 0; j < segments; ++j) {
      f.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      f.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    }
  for (int j = 0; j < segments; ++j) f.push_back({nv - 1, id(rings - 1, j), id(rings - 1, j + 1)});
  m.F.resize(static_cast<int>(f.size()), 3);
  for (size_t k = 0; k < f.size(); ++k) m.F.row(k) << f[k][0], f[k][1], f[k][2];
  return m;
}
}  // namespace

gdsr::TriMesh make_sphere(const Vec3& c, double r, int rings, int segments) {
  auto m = revolve(
      [&](double t) {
        const double th = kPi * t;
        return std::pair<double, double>(r * std::sin(th), c.y() - r * std::cos(th));
      },
      c.x(), c.z(), rings, segments);
  return m;
}

gdsr::TriMesh make_capsule(double x, double z, double y0, double y1, double r, int rings, int segments) {
  if (!(y1 - y0 > 2 * r)) throw std::runtime_error("sim/cloth_bodies: capsule shorter than its caps");
  const double L = y1 - y0 - 2 * r;
  const double total = kPi * r + L;  // profile arc length
  return revolve(
      [&](double t) {
        const double s = t * total;
        if (s < kPi * r / 2) {
          const double th = s / r;
          return std::pair<double, double>(r * std::sin(th), y0 + r - r * std::cos(th));
        }
        if (s < kPi * r / 2 + L) return std::pair<double, double>(r, y0 + r + (s - kPi * r / 2));
        const double th = (s - kPi * r / 2 - L) / r;
        return std::pair<double, double>(r * std::cos(th), y1 - r + r * std::sin(th));
      },
      x, z, rings, segments);
}

gdsr::TriMesh merge_meshes(const gdsr::TriMesh& a, const gdsr::TriMesh& b) {
  gdsr::TriMesh m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F.topRows(a.F.rows()) = a.F;
  m.F.bottomRows(b.F.rows()) = b.F.array() + static_cast<int>(a.V.rows());
  return m;
}

gdsr::TriMesh make_mannequin(double height) {
  const double s = height / 1.62;
  auto trunk = make_capsule(0, 0, 0.78 * s, 1.62 * s, 0.15 * s, 40, 48);
  auto legl = make_capsule(-0.085 * s, 0, 0, 0.95 * s, 0.075 * s, 40, 24);
  auto legr = make_capsule(0.085 * s, 0, 0, 0.95 * s, 0.075 * s, 40, 24);
  return merge_meshes(merge_meshes(trunk, legl), legr);
}

}  // namespace sim

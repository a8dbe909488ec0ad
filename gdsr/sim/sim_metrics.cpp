#include "gdsr/sim/sim_metrics.hpp"

#include "gdsr/error.hpp"

#include "gdsr/body/body_query.hpp"
#include "gdsr/geometry/triangle.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace sim {

using gdsr::Points3;
using gdsr::Vec2;
using gdsr::Vec3;

Penetration body_penetration(const Points3& X, const gdsr::Faces& body_F, const Points3& body_V, double radius) {
  // Embree closest points with the pseudonormal sign (gdsr/body/body_query.hpp): independent of
  // the solver's own contact grid (sim/cloth_collision.hpp), so the figure can catch its mistakes.
  Penetration p;
  if (body_F.rows() == 0 || X.rows() == 0) return p;
  const gdsr::BodyQuery query(gdsr::TriMesh{body_V, body_F});
  const gdsr::ClosestPoints c = query.closest(X, /*smooth_normals=*/false, radius);
  double sum = 0;
  for (int v = 0; v < X.rows(); ++v) {
    if (c.face(v) >= 0 && c.sdist(v) < 0) {
      p.max_depth = std::max(p.max_depth, -c.sdist(v));
      sum += -c.sdist(v);
      ++p.count;
    }
  }
  p.mean_depth = sum / X.rows();
  return p;
}

double kinetic_energy(const gdsr::GarmentMesh& g, const Points3& X0, const Points3& X1, double dt, double density) {
  std::vector<double> m(g.V.rows(), 0.0);
  for (int f = 0; f < g.F.rows(); ++f) {
    const Vec2 a = g.UV.row(g.FUV(f, 0)), b = g.UV.row(g.FUV(f, 1)), c = g.UV.row(g.FUV(f, 2));
    const double area = 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    for (int k = 0; k < 3; ++k) m[g.F(f, k)] += density * area / 3;
  }
  double e = 0;
  for (int v = 0; v < X0.rows(); ++v) e += 0.5 * m[v] * ((X1.row(v) - X0.row(v)) / dt).squaredNorm();
  return e;
}

Points3 resample_by_uv(const gdsr::GarmentMesh& from, const Points3& from_X, const gdsr::GarmentMesh& to) {
  if (from_X.rows() != from.V.rows()) gdsr::fail("sim/sim_metrics", "positions do not match the source garment");
  // Uniform grid over the source UV triangles' boxes.
  const double cell = 0.05;
  std::map<std::pair<int, int>, std::vector<int>> grid;
  for (int f = 0; f < from.FUV.rows(); ++f) {
    Vec2 lo = from.UV.row(from.FUV(f, 0)), hi = lo;
    for (int k = 1; k < 3; ++k) {
      lo = lo.cwiseMin(Vec2(from.UV.row(from.FUV(f, k))));
      hi = hi.cwiseMax(Vec2(from.UV.row(from.FUV(f, k))));
    }
    for (int i = static_cast<int>(std::floor(lo.x() / cell)); i <= static_cast<int>(std::floor(hi.x() / cell)); ++i)
      for (int j = static_cast<int>(std::floor(lo.y() / cell)); j <= static_cast<int>(std::floor(hi.y() / cell)); ++j)
        grid[{i, j}].push_back(f);
  }
  Points3 out = Points3::Zero(to.V.rows(), 3);
  std::vector<int> count(to.V.rows(), 0);
  for (int u = 0; u < to.UV.rows(); ++u) {
    const Vec3 q(to.UV(u, 0), to.UV(u, 1), 0);
    double best = 1e300;
    int bf = -1;
    Vec3 bb = Vec3::Zero();
    const int ci = static_cast<int>(std::floor(q.x() / cell)), cj = static_cast<int>(std::floor(q.y() / cell));
    int found_ring = -1;
    for (int ring = 0; ring < 2000; ++ring) {  // square rings of cells; one extra ring after a hit
      for (int i = ci - ring; i <= ci + ring; ++i)
        for (int j = cj - ring; j <= cj + ring; ++j) {
          if (std::max(std::abs(i - ci), std::abs(j - cj)) != ring) continue;
          auto it = grid.find({i, j});
          if (it == grid.end()) continue;
          for (int f : it->second) {
            auto p3 = [&](int k) { return Vec3(from.UV(from.FUV(f, k), 0), from.UV(from.FUV(f, k), 1), 0); };
            const Vec3 b = gdsr::closest_point_on_triangle(q, p3(0), p3(1), p3(2)).bary;
            const double d = (b.x() * p3(0) + b.y() * p3(1) + b.z() * p3(2) - q).squaredNorm();
            if (d < best) {
              best = d;
              bf = f;
              bb = b;
            }
          }
        }
      if (bf >= 0 && found_ring < 0) found_ring = ring;
      if (found_ring >= 0 && ring > found_ring) break;
    }
    if (bf < 0) gdsr::fail("sim/sim_metrics", "source garment has no UV triangles");
    Vec3 x = Vec3::Zero();
    for (int k = 0; k < 3; ++k) x += bb(k) * from_X.row(from.F(bf, k)).transpose();
    out.row(to.uv_to_vertex[u]) += x.transpose();
    ++count[to.uv_to_vertex[u]];
  }
  for (int v = 0; v < out.rows(); ++v) out.row(v) /= std::max(1, count[v]);
  return out;
}

std::vector<FrameMetrics> sequence_metrics(const gdsr::GarmentMesh& g, const std::vector<Points3>& frames,
                                           const gdsr::Faces& body_F, const std::vector<Points3>& body_frames,
                                           double fps, double density) {
  std::vector<FrameMetrics> out(frames.size());
  for (size_t t = 0; t < frames.size(); ++t) {
    out[t].strain = gdsr::strain_energies(g, frames[t]);
    if (t < body_frames.size()) out[t].penetration = body_penetration(frames[t], body_F, body_frames[t]);
    if (t > 0) out[t].kinetic_energy = kinetic_energy(g, frames[t - 1], frames[t], 1.0 / fps, density);
    out[t].wrinkles = wrinkle_measure(frames[t], g.F);
  }
  return out;
}

}  // namespace sim

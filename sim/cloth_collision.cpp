#include "sim/cloth_collision.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sim {

using gdsr::Vec3;

Vec3 closest_point_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson, Real-Time Collision Detection, 5.1.5.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return Vec3(1, 0, 0);
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return Vec3(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return Vec3(1 - v, v, 0);
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return Vec3(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return Vec3(1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return Vec3(0, 1 - w, w);
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) return Vec3(1, 0, 0);  // degenerate triangle
  const double v = vb / denom, w = vc / denom;
  return Vec3(1 - v - w, v, w);
}

long long SurfaceGrid::key(int i, int j, int k) const {
  const long long m = 1 << 20;
  return ((static_cast<long long>(i) + m / 2) * m + (j + m / 2)) * m + (k + m / 2);
}

void SurfaceGrid::build(const gdsr::Faces& F, const gdsr::Points3& V0, const gdsr::Points3& V1,
                        double cell) {
  if (!(cell > 0)) throw std::runtime_error("sim/cloth_collision: grid cell must be positive");
  if (V0.rows() != V1.rows()) throw std::runtime_error("sim/cloth_collision: pose vertex counts differ");
  F_ = &F;
  cell_ = cell;
  cells_.clear();
  if (V0.rows() == 0) return;
  origin_ = V0.colwise().minCoeff().transpose();
  for (int f = 0; f < F.rows(); ++f) {
    Vec3 lo = V0.row(F(f, 0)).transpose(), hi = lo;
    for (int k = 0; k < 3; ++k) {
      lo = lo.cwiseMin(V0.row(F(f, k)).transpose()).cwiseMin(V1.row(F(f, k)).transpose());
      hi = hi.cwiseMax(V0.row(F(f, k)).transpose()).cwiseMax(V1.row(F(f, k)).transpose());
    }
    const Eigen::Vector3i a = ((lo - origin_) / cell_).array().floor().cast<int>();
    const Eigen::Vector3i b = ((hi - origin_) / cell_).array().floor().cast<int>();
    for (int i = a.x(); i <= b.x(); ++i)
      for (int j = a.y(); j <= b.y(); ++j)
        for (int k = a.z(); k <= b.z(); ++k) cells_[key(i, j, k)].push_back(f);
  }
}

SurfaceHit SurfaceGrid::closest(const Vec3& x, const gdsr::Points3& V, double radius) const {
  SurfaceHit hit;
  if (cells_.empty()) return hit;
  const auto& F = *F_;
  const Eigen::Vector3i a = ((x.array() - radius - origin_.array()) / cell_).floor().cast<int>();
  const Eigen::Vector3i b = ((x.array() + radius - origin_.array()) / cell_).floor().cast<int>();
  double best = radius * radius;
  std::vector<int> cand;
  for (int i = a.x(); i <= b.x(); ++i)
    for (int j = a.y(); j <= b.y(); ++j)
      for (int k = a.z(); k <= b.z(); ++k) {
        auto it = cells_.find(key(i, j, k));
        if (it != cells_.end()) cand.insert(cand.end(), it->second.begin(), it->second.end());
      }
  std::sort(cand.begin(), cand.end());
  cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
  Vec3 nsum = Vec3::Zero();
  for (int f : cand) {
    const Vec3 p0 = V.row(F(f, 0)), p1 = V.row(F(f, 1)), p2 = V.row(F(f, 2));
    const Vec3 bc = closest_point_triangle(x, p0, p1, p2);
    const Vec3 q = bc.x() * p0 + bc.y() * p1 + bc.z() * p2;
    const double d2 = (x - q).squaredNorm();
    const Vec3 n = (p1 - p0).cross(p2 - p0).normalized();
    if (d2 < best - 1e-14) {
      best = d2;
      hit.face = f;
      hit.bary = bc;
      hit.point = q;
      nsum = n;
    } else if (hit.face >= 0 && d2 <= best + 1e-14) {
      nsum += n;  // shared edge/vertex: average the faces' normals
    }
  }
  if (hit.face < 0) return hit;
  hit.normal = nsum.norm() > 0 ? Vec3(nsum.normalized()) : Vec3(0, 1, 0);
  const double d = std::sqrt(best);
  hit.signed_distance = (x - hit.point).dot(hit.normal) >= 0 ? d : -d;
  return hit;
}

}  // namespace sim

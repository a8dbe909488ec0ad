// Exact primitive tests shared by cloth self-collision's narrow phase, its contact projection
// and its untangling: closest points of two segments, a segment crossing a triangle, a point
// projected onto a triangle's plane. Lengths in metres (any unit works: nothing is scaled).
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace sim {

// Closest points of segments p1q1 and p2q2 (Ericson, Real-Time Collision Detection 5.1.9):
// parameters s (on the first) and t (on the second) in [0, 1].
inline void closest_segments(const gdsr::Vec3& p1, const gdsr::Vec3& q1, const gdsr::Vec3& p2, const gdsr::Vec3& q2,
                             double& s, double& t) {
  const gdsr::Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double eps = 1e-30;
  if (a <= eps && e <= eps) {
    s = t = 0;
    return;
  }
  if (a <= eps) {
    s = 0;
    t = std::clamp(f / e, 0.0, 1.0);
    return;
  }
  const double c = d1.dot(r);
  if (e <= eps) {
    t = 0;
    s = std::clamp(-c / a, 0.0, 1.0);
    return;
  }
  const double b = d1.dot(d2), denom = a * e - b * b;
  s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  t = (b * s + f) / e;
  if (t < 0) {
    t = 0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1) {
    t = 1;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
}

// Does segment pq cross triangle abc (proper crossing; touching does not count)?
inline bool segment_crosses_triangle(const gdsr::Vec3& p, const gdsr::Vec3& q, const gdsr::Vec3& a, const gdsr::Vec3& b,
                                     const gdsr::Vec3& c) {
  const gdsr::Vec3 n = (b - a).cross(c - a);
  const double dp = n.dot(p - a), dq = n.dot(q - a);
  if ((dp > 0) == (dq > 0) || dp == 0 || dq == 0) return false;
  const gdsr::Vec3 d = q - p;
  const double s1 = (a - p).cross(b - p).dot(d);
  const double s2 = (b - p).cross(c - p).dot(d);
  const double s3 = (c - p).cross(a - p).dot(d);
  return (s1 > 0 && s2 > 0 && s3 > 0) || (s1 < 0 && s2 < 0 && s3 < 0);
}

// Barycentric coordinates of the projection of p onto the plane of abc, and the signed
// distance along the unit normal n (b - a) x (c - a). False for a degenerate triangle.
inline bool project_on_triangle(const gdsr::Vec3& p, const gdsr::Vec3& a, const gdsr::Vec3& b, const gdsr::Vec3& c,
                                gdsr::Vec3& bary, gdsr::Vec3& n, double& dist) {
  const gdsr::Vec3 e1 = b - a, e2 = c - a;
  n = e1.cross(e2);
  const double n2 = n.squaredNorm();
  if (!(n2 > 1e-30)) return false;
  const gdsr::Vec3 ap = p - a;
  const double w1 = ap.cross(e2).dot(n) / n2;  // weight of b
  const double w2 = e1.cross(ap).dot(n) / n2;  // weight of c
  bary = gdsr::Vec3(1 - w1 - w2, w1, w2);
  n /= std::sqrt(n2);
  dist = ap.dot(n);
  return true;
}

}  // namespace sim

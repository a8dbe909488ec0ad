// Brute-force body contact for tests: the exact nearest point on a small triangle mesh,
// O(V x F) (gdsr/body/body_query.hpp is the fast Embree path the model uses). Normal: the
// face normal of the nearest triangle (outward for CCW faces).
#pragma once

#include "gdsr/error.hpp"
#include "gdsr/geometry/triangle.hpp"
#include "gdsr/model/features.hpp"

#include <limits>

namespace gdsr_test {

inline gdsr::BodyContact closest_points_bruteforce(const gdsr::TriMesh& body, const gdsr::Points3& q) {
  using gdsr::BodyContact;
  using gdsr::closest_point_on_triangle;
  using gdsr::Vec3;
  if (body.F.rows() == 0) gdsr::fail("body_contact", "closest_points_bruteforce on an empty body");
  BodyContact out;
  out.point.resize(q.rows(), 3);
  out.normal.resize(q.rows(), 3);
  for (int i = 0; i < q.rows(); ++i) {
    const Vec3 p = q.row(i).transpose();
    double best = std::numeric_limits<double>::infinity();
    for (int f = 0; f < body.F.rows(); ++f) {
      const Vec3 a = body.V.row(body.F(f, 0)).transpose(), b = body.V.row(body.F(f, 1)).transpose(),
                 c = body.V.row(body.F(f, 2)).transpose();
      const Vec3 x = closest_point_on_triangle(p, a, b, c).point;
      const double d = (x - p).squaredNorm();
      if (d < best) {
        best = d;
        out.point.row(i) = x.transpose();
        const Vec3 n = (b - a).cross(c - a);
        const double len = n.norm();
        out.normal.row(i) = (len > 0 ? Vec3(n / len) : Vec3::Zero()).transpose();
      }
    }
  }
  return out;
}

}  // namespace gdsr_test

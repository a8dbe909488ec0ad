#include "gdsr/geometry/triangle.hpp"

#include <cmath>

namespace gdsr {

TriangleClosest closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  using R = TriangleRegion;
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, Vec3(1, 0, 0), R::VertexA};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, Vec3(0, 1, 0), R::VertexB};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    return {a + t * ab, Vec3(1 - t, t, 0), R::EdgeAB};
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, Vec3(0, 0, 1), R::VertexC};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    return {a + t * ac, Vec3(1 - t, 0, t), R::EdgeCA};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + t * (c - b), Vec3(0, 1 - t, t), R::EdgeBC};
  }
  const double den = va + vb + vc;
  if (!(std::abs(den) > 0)) return {a, Vec3(1, 0, 0), R::VertexA};  // degenerate triangle
  const double v = vb / den, w = vc / den;
  return {a + ab * v + ac * w, Vec3(1 - v - w, v, w), R::Face};
}

}  // namespace gdsr

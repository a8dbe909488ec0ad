#include "gdsr/features.hpp"

#include "autograd/autograd.hpp"
#include "gdsr/model_geometry.hpp"

#include <limits>
#include <stdexcept>
#include <string>

namespace gdsr {

namespace {

// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection 5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

void check_rows(const char* what, const Points3& P, int V) {
  if (P.rows() != V)
    throw std::runtime_error(std::string("features: ") + what + " has " + std::to_string(P.rows()) +
                             " rows, the garment has " + std::to_string(V) + " vertices");
}

// [E x 4]: x[dst] - x[src] and its length, for constant positions.
template <class T>
RowMat4<T> dummy();

}  // namespace

BodyContact closest_points_bruteforce(const TriMesh& body, const Points3& q) {
  if (body.F.rows() == 0) throw std::runtime_error("features: closest_points_bruteforce on an empty body");
  BodyContact out;
  out.point.resize(q.rows(), 3);
  out.normal.resize(q.rows(), 3);
  for (int i = 0; i < q.rows(); ++i) {
    const Vec3 p = q.row(i).transpose();
    double best = std::numeric_limits<double>::infinity();
    for (int f = 0; f < body.F.rows(); ++f) {
      const Vec3 a = body.V.row(body.F(f, 0)).transpose(), b = body.V.row(body.F(f, 1)).transpose(),
                 c = body.V.row(body.F(f, 2)).transpose();
      const Vec3 x = closest_on_triangle(p, a, b, c);
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

}  // namespace gdsr

#include "gdsr/body/body.hpp"
#include "gdsr/body/body_query.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/triangle.hpp"

#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>
#include <random>

using namespace gdsr;

namespace {

// Icosphere of radius r (closed, outward), `levels` subdivisions.
TriMesh bq_icosphere(double r, int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Eigen::Vector3i> f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                    {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto m = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<Eigen::Vector3i> g;
    for (auto& t3 : f) {
      const int a = m(t3[0], t3[1]), b = m(t3[1], t3[2]), c = m(t3[2], t3[0]);
      g.push_back({t3[0], a, c});
      g.push_back({t3[1], b, a});
      g.push_back({t3[2], c, b});
      g.push_back({a, b, c});
    }
    f = g;
  }
  TriMesh mesh;
  mesh.V.resize(v.size(), 3);
  for (size_t i = 0; i < v.size(); ++i) mesh.V.row(i) = r * v[i].transpose();
  mesh.F.resize(f.size(), 3);
  for (size_t i = 0; i < f.size(); ++i) mesh.F.row(i) = f[i].transpose();
  return mesh;
}

TriMesh bq_cube(double h) {  // axis-aligned cube [-h, h]^3, outward
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.V.row(i) << ((i & 1) ? h : -h), ((i & 2) ? h : -h), ((i & 4) ? h : -h);
  m.F.resize(12, 3);
  m.F << 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5;
  return m;
}

// Independent brute force: distance from p to triangle by plane projection / edge segments.
double tri_dist(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double nn = n.squaredNorm();
  if (nn > 0) {
    const Vec3 q = p - n * ((p - a).dot(n) / nn);
    const double s0 = (b - a).cross(q - a).dot(n), s1 = (c - b).cross(q - b).dot(n), s2 = (a - c).cross(q - c).dot(n);
    if (s0 >= 0 && s1 >= 0 && s2 >= 0) return (p - q).norm();
  }
  auto seg = [&](const Vec3& x, const Vec3& y) {
    const double t = std::clamp((p - x).dot(y - x) / std::max((y - x).squaredNorm(), 1e-300), 0.0, 1.0);
    return (p - (x + t * (y - x))).norm();
  };
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}

// Generalised winding number (solid angles / 4 pi): ~1 inside a closed outward mesh, ~0 outside.
double winding(const TriMesh& m, const Vec3& p) {
  double w = 0;
  for (int f = 0; f < m.F.rows(); ++f) {
    const Vec3 a = Vec3(m.V.row(m.F(f, 0))) - p, b = Vec3(m.V.row(m.F(f, 1))) - p, c = Vec3(m.V.row(m.F(f, 2))) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    w += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return w / (4 * M_PI);
}

// Compares BodyQuery::closest with brute force on Q; returns the number of sign mismatches.
void check_against_brute_force(const TriMesh& m, const Points3& Q) {
  const BodyQuery bq(m);
  const ClosestPoints r = bq.closest(Q);
  int dist_bad = 0, sign_bad = 0, point_bad = 0;
  for (int i = 0; i < Q.rows(); ++i) {
    const Vec3 q = Q.row(i);
    double best = 1e300;
    for (int f = 0; f < m.F.rows(); ++f)
      best = std::min(best, tri_dist(q, m.V.row(m.F(f, 0)), m.V.row(m.F(f, 1)), m.V.row(m.F(f, 2))));
    if (std::abs(std::abs(r.sdist[i]) - best) > 1e-9 + 1e-7 * best) ++dist_bad;
    // The returned point lies on the returned face at the returned distance.
    const int f = r.face[i];
    const Vec3 fromb = r.bary(i, 0) * Vec3(m.V.row(m.F(f, 0))) + r.bary(i, 1) * Vec3(m.V.row(m.F(f, 1))) +
                       r.bary(i, 2) * Vec3(m.V.row(m.F(f, 2)));
    if ((fromb - Vec3(r.point.row(i))).norm() > 1e-9 || std::abs((q - fromb).norm() - best) > 1e-9 + 1e-7 * best)
      ++point_bad;
    const double w = winding(m, q);
    if (best > 1e-9 && ((w > 0.5) != (r.sdist[i] < 0))) ++sign_bad;
    CHECK(std::abs(r.normal.row(i).norm() - 1) < 1e-9);
  }
  CHECK(dist_bad == 0);
  CHECK(point_bad == 0);
  CHECK(sign_bad == 0);
}

}  // namespace

TEST_CASE("body_query: closest point and signed distance match brute force on a sphere") {
  const TriMesh s = bq_icosphere(0.3, 3);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1, 1), N(-0.02, 0.02);
  Points3 Q(700, 3);
  for (int i = 0; i < 300; ++i) Q.row(i) << U(rng), U(rng), U(rng);  // near and far, inside and out
  for (int i = 300; i < 700; ++i) {  // close to the surface, both sides, around vertices/edges
    const int v = static_cast<int>(rng() % s.V.rows());
    const int w = s.F(rng() % s.F.rows(), 0);
    const Vec3 p = (i % 2) ? Vec3(s.V.row(v)) : Vec3(0.5 * (s.V.row(v) + s.V.row(w)));
    Q.row(i) = (p * (1 + N(rng) / 0.3)).transpose();
  }
  check_against_brute_force(s, Q);
  // Smooth normal ~ radial direction on a sphere.
  const ClosestPoints r = BodyQuery(s).closest(Q);
  for (int i = 0; i < Q.rows(); ++i) CHECK(r.normal.row(i).dot(r.point.row(i).normalized()) > 0.99);
}

TEST_CASE("body_query: any_face_within agrees with brute force, only over accepted faces") {
  // Random points near a sphere; the accepted faces are those with an even index. Brute force:
  // the exact distance to every accepted triangle (closest_point_on_triangle), compared with
  // the radius away from ties.
  const TriMesh s = bq_icosphere(0.3, 2);
  const BodyQuery bq(s);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-0.5, 0.5), R(0.001, 0.1);
  auto even = [](int f) { return f % 2 == 0; };
  int found = 0, missed = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3 q(U(rng), U(rng), U(rng));
    const double radius = R(rng);
    double best = std::numeric_limits<double>::infinity();
    for (int f = 0; f < s.F.rows(); f += 2)
      best = std::min(
          best,
          (closest_point_on_triangle(q, s.V.row(s.F(f, 0)), s.V.row(s.F(f, 1)), s.V.row(s.F(f, 2))).point - q).norm());
    if (std::abs(best - radius) < 1e-9) continue;
    const bool hit = bq.any_face_within(q, radius, even);
    CHECK(hit == (best <= radius));
    (hit ? found : missed)++;
  }
  CHECK(found > 25);  // both answers occur
  CHECK(missed > 25);
  CHECK_FALSE(bq.any_face_within(Vec3(0, 0, 0.3), 0.05, [](int) { return false; }));
  CHECK_THROWS_AS(bq.any_face_within(Vec3(0, 0, NAN), 0.05, even), gdsr::Error);
}

TEST_CASE("body_query: signs at cube edges and corners") {
  const TriMesh c = bq_cube(0.5);
  const BodyQuery bq(c);
  Points3 Q(8, 3);
  const double d = 1e-4;
  Q << 0.5 + d, 0.5 + d, 0.5 + d,   // outside a corner
      0.5 - d, 0.5 - d, 0.5 - d,    // inside a corner
      0.5 + d, 0.5 + d, 0.0,        // outside an edge
      0.5 - d, 0.5 - d, 0.1,        // inside an edge
      0.5 + d, 0.0, 0.0,            // outside a face
      0.0, 0.0, 0.0,                // centre
      2.0, 2.0, 2.0,                // far outside corner
      -0.5 - d, 0.5 + d, -0.5 - d;  // another outside corner
  const ClosestPoints r = bq.closest(Q);
  CHECK(r.sdist[0] == doctest::Approx(d * std::sqrt(3.0)));
  CHECK(r.sdist[1] == doctest::Approx(-d));
  CHECK(r.sdist[2] == doctest::Approx(d * std::sqrt(2.0)));
  CHECK(r.sdist[3] == doctest::Approx(-d));
  CHECK(r.sdist[4] == doctest::Approx(d));
  CHECK(r.sdist[5] == doctest::Approx(-0.5));
  CHECK(r.sdist[6] == doctest::Approx(1.5 * std::sqrt(3.0)));
  CHECK(r.sdist[7] == doctest::Approx(d * std::sqrt(3.0)));
  // Pseudonormal mode: at a corner the normal is the (normalised) diagonal.
  const ClosestPoints p = bq.closest(Q, false);
  CHECK(p.normal.row(0).dot(Eigen::RowVector3d(1, 1, 1).normalized()) == doctest::Approx(1.0));
  CHECK(p.normal.row(4).dot(Eigen::RowVector3d(1, 0, 0)) == doctest::Approx(1.0));
  // max_distance: far points report no face.
  const ClosestPoints m = bq.closest(Q, true, 0.1);
  CHECK(m.face[6] == -1);
  CHECK(std::isinf(m.sdist[6]));
  CHECK(m.face[0] >= 0);
}

TEST_CASE("body_query: closest point matches brute force on the body") {
  BodyOptions o;
  o.max_seconds = 0.2;
  const BodySequence seq = load_body_sequence("/usr/share/assimp/models/BVH/01_03.bvh", o);
  const TriMesh body = seq.frame_mesh(seq.num_frames() - 1);
  std::mt19937 rng(7);
  const Eigen::RowVector3d lo = body.V.colwise().minCoeff(), hi = body.V.colwise().maxCoeff();
  std::uniform_real_distribution<double> U(0, 1), N(-0.03, 0.03);
  Points3 Q(400, 3);
  for (int i = 0; i < 150; ++i)
    for (int k = 0; k < 3; ++k) Q(i, k) = lo[k] - 0.2 + (hi[k] - lo[k] + 0.4) * U(rng);
  const BodyQuery bq(body);
  for (int i = 150; i < 400; ++i) {  // garment-like points: within 3 cm of the surface
    const int v = static_cast<int>(rng() % body.V.rows());
    Q.row(i) = body.V.row(v) + N(rng) * bq.vertex_normals().row(v);
  }
  check_against_brute_force(body, Q);
}

TEST_CASE("body_query: rays hit a cube where expected") {
  const TriMesh c = bq_cube(0.5);
  const BodyQuery bq(c);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-0.9, 0.9);
  const int n = 200;
  Points3 O(n, 3), D(n, 3);
  for (int i = 0; i < n; ++i) {
    O.row(i) << U(rng), U(rng), 5.0;
    D.row(i) << 0, 0, -2.0;  // not unit: t is in units of |D|
  }
  const RayHits h = bq.intersect(O, D);
  int hits = 0;
  for (int i = 0; i < n; ++i) {
    const bool inside = std::abs(O(i, 0)) < 0.5 && std::abs(O(i, 1)) < 0.5;
    if (std::abs(std::abs(O(i, 0)) - 0.5) < 1e-4 || std::abs(std::abs(O(i, 1)) - 0.5) < 1e-4) continue;
    CHECK((h.face[i] >= 0) == inside);
    if (!inside) {
      CHECK(std::isinf(h.t[i]));
      continue;
    }
    ++hits;
    CHECK(h.t[i] == doctest::Approx(2.25).epsilon(1e-6));
    const int f = h.face[i];
    CHECK(bq.face_normals()(f, 2) == doctest::Approx(1.0));  // the +z face
    const double u = h.uv(i, 0), v = h.uv(i, 1);
    const Vec3 p = (1 - u - v) * Vec3(c.V.row(c.F(f, 0))) + u * Vec3(c.V.row(c.F(f, 1))) + v * Vec3(c.V.row(c.F(f, 2)));
    CHECK((p - Vec3(O.row(i) + h.t[i] * D.row(i))).norm() < 1e-5);
  }
  CHECK(hits > 20);
  // tmax cuts the hit off; a ray from inside hits the far side.
  CHECK(bq.intersect(O.topRows(1), D.topRows(1), 0, 1.0).face[0] == -1);
  Points3 o0(1, 3), d0(1, 3);
  o0 << 0.1, 0.2, 0;
  d0 << 1, 0, 0;
  const RayHits in = bq.intersect(o0, d0);
  CHECK(in.t[0] == doctest::Approx(0.4));
}

TEST_CASE("body_query: update moves the surface / bad input gives clear errors") {
  const TriMesh s = bq_icosphere(0.3, 2);
  BodyQuery bq(s);
  Points3 Q(3, 3);
  Q << 1, 0, 0, 0, 0.9, 0, 0.1, 0.1, 0.1;
  TriMesh moved = s;
  moved.V.col(0).array() += 0.5;
  bq.update(moved.V);
  const ClosestPoints a = bq.closest(Q), b = BodyQuery(moved).closest(Q);
  CHECK((a.point - b.point).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((a.sdist - b.sdist).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(a.sdist[0] == doctest::Approx(0.2).epsilon(0.01));  // x = 1 vs sphere centred at 0.5
  BodyQuery refit(s, BodyQuery::Update::Refit);
  refit.update(moved.V);
  CHECK((refit.closest(Q).sdist - b.sdist).cwiseAbs().maxCoeff() < 1e-12);

  CHECK_THROWS_WITH_AS(BodyQuery(TriMesh{}), doctest::Contains("empty mesh"), std::runtime_error);
  Points3 bad = Q;
  bad(1, 2) = std::nan("");
  CHECK_THROWS_WITH_AS(bq.closest(bad), doctest::Contains("query point 1"), std::runtime_error);
  CHECK_THROWS_AS(bq.intersect(bad, Q), std::runtime_error);
  Points3 zero = Points3::Zero(3, 3);
  CHECK_THROWS_WITH_AS(bq.intersect(Q, zero), doctest::Contains("zero ray direction"), std::runtime_error);
  CHECK_THROWS_WITH_AS(bq.update(Q), doctest::Contains("vertices"), std::runtime_error);
  Points3 nanV = s.V;
  nanV(5, 0) = std::nan("");
  CHECK_THROWS_WITH_AS(bq.update(nanV), doctest::Contains("vertex 5"), std::runtime_error);
  TriMesh badF = s;
  badF.F(0, 0) = 100000;
  CHECK_THROWS_WITH_AS(BodyQuery{badF}, doctest::Contains("face index"), std::runtime_error);
}

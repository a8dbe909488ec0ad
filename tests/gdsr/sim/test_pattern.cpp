#include <doctest/doctest.h>

#include "gdsr/sim/pattern.hpp"

#include <algorithm>
#include <cmath>
#include <set>

using gdsr::Vec2;

namespace {

sim::Pattern two_squares_pattern(double side) {
  // Two squares side by side with a gap; right edge of A (edge 1) sewn to left edge of B (3).
  sim::Pattern p;
  p.panels.push_back({"A", {Vec2(0, 0), Vec2(side, 0), Vec2(side, side), Vec2(0, side)}});
  const double o = side + 0.1;
  p.panels.push_back({"B", {Vec2(o, 0), Vec2(o + side, 0), Vec2(o + side, side), Vec2(o, side)}});
  p.seams.push_back({0, 1, 1, 3, true});
  return p;
}

sim::Pattern flared_pattern() {
  // A non-convex panel (annular sector) and a trapezoid.
  sim::Pattern p;
  std::vector<Vec2> o = sim::arc_points(Vec2(0, 0), 0.6, 0.3, 1.4, 20);
  std::vector<Vec2> inner = sim::arc_points(Vec2(0, 0), 0.25, 1.4, 0.3, 8);
  o.insert(o.end(), inner.begin(), inner.end());
  p.panels.push_back({"sector", o});
  p.panels.push_back({"trap", {Vec2(1, 0), Vec2(1.5, 0), Vec2(1.4, 0.3), Vec2(1.1, 0.3)}});
  return p;
}

double mean_uv_edge(const gdsr::GarmentMesh& m) {
  std::set<std::pair<int, int>> edges;
  for (int f = 0; f < m.FUV.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      int a = m.FUV(f, k), b = m.FUV(f, (k + 1) % 3);
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  double s = 0;
  for (auto& e : edges) s += (m.UV.row(e.first) - m.UV.row(e.second)).norm();
  return s / edges.size();
}

double total_uv_area(const gdsr::GarmentMesh& m) {
  double a = 0;
  for (int f = 0; f < m.FUV.rows(); ++f) {
    Vec2 p0 = m.UV.row(m.FUV(f, 0)), p1 = m.UV.row(m.FUV(f, 1)), p2 = m.UV.row(m.FUV(f, 2));
    Vec2 e1 = p1 - p0, e2 = p2 - p0;
    a += 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  }
  return a;
}

// Distance of UV point q to the pattern outline of its panel.
double dist_to_outline(const std::vector<Vec2>& o, const Vec2& q) {
  double best = 1e9;
  for (size_t e = 0; e < o.size(); ++e) {
    Vec2 a = o[e], b = o[(e + 1) % o.size()];
    double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    best = std::min(best, (a + t * (b - a) - q).norm());
  }
  return best;
}

}  // namespace

TEST_CASE("pattern: meshing gives the requested edge length at 30 mm and 10 mm") {
  for (double h : {0.03, 0.01}) {
    for (const auto& p : {two_squares_pattern(0.5), flared_pattern()}) {
      auto pm = sim::mesh_pattern(p, h);
      const double mean = mean_uv_edge(pm.mesh);
      CAPTURE(h);
      CAPTURE(mean);
      CHECK(std::abs(mean - h) < 0.2 * h);
      // Area preserved, all triangles counter-clockwise (positive) in UV.
      double area = 0;
      for (auto& pan : p.panels) area += sim::polygon_area(pan.outline);
      CHECK(total_uv_area(pm.mesh) == doctest::Approx(area).epsilon(1e-9));
      for (int f = 0; f < pm.mesh.FUV.rows(); ++f) {
        Vec2 p0 = pm.mesh.UV.row(pm.mesh.FUV(f, 0)), p1 = pm.mesh.UV.row(pm.mesh.FUV(f, 1)),
             p2 = pm.mesh.UV.row(pm.mesh.FUV(f, 2));
        Vec2 e1 = p1 - p0, e2 = p2 - p0;
        REQUIRE(e1.x() * e2.y() - e1.y() * e2.x() > 0);
        // Near-uniform triangles: no angle below 20 degrees.
        const Vec2 q[3] = {p0, p1, p2};
        for (int k = 0; k < 3; ++k) {
          const Vec2 a = (q[(k + 1) % 3] - q[k]).normalized(), b = (q[(k + 2) % 3] - q[k]).normalized();
          CHECK(std::acos(std::clamp(a.dot(b), -1.0, 1.0)) > 20.0 * M_PI / 180);
        }
      }
    }
  }
}

TEST_CASE("pattern: LR and HR share the same UV outline") {
  auto p = flared_pattern();
  auto lr = sim::mesh_pattern(p, 0.03);
  auto hr = sim::mesh_pattern(p, 0.01);
  for (const auto* pm : {&lr, &hr}) {
    // Every boundary UV vertex lies on the polygon; every polygon corner is a UV vertex.
    for (int u = 0; u < pm->mesh.UV.rows(); ++u) {
      if (pm->uv_boundary[u] < 0) continue;
      const auto& o = p.panels[pm->uv_panel[u]].outline;
      CHECK(dist_to_outline(o, Vec2(pm->mesh.UV.row(u))) < 1e-12);
    }
    for (size_t i = 0; i < p.panels.size(); ++i)
      for (const auto& c : p.panels[i].outline) {
        double best = 1e9;
        for (int u = 0; u < pm->mesh.UV.rows(); ++u) best = std::min(best, (Vec2(pm->mesh.UV.row(u)) - c).norm());
        CHECK(best < 1e-12);
      }
  }
  CHECK(total_uv_area(lr.mesh) == doctest::Approx(total_uv_area(hr.mesh)).epsilon(1e-9));
  CHECK(hr.mesh.UV.rows() > 5 * lr.mesh.UV.rows());
}

TEST_CASE("pattern: seam vertices weld one to one") {
  for (double h : {0.03, 0.011}) {
    auto p = two_squares_pattern(0.4);
    p.panels[1].outline[3] = Vec2(0.5, 0.43);  // B's left edge slightly longer than A's right edge
    auto pm = sim::mesh_pattern(p, h);
    const auto& m = pm.mesh;
    std::vector<int> a, b;  // UV vertices on the sewn edges
    for (int u = 0; u < m.UV.rows(); ++u) {
      const bool on_a = pm.uv_panel[u] == 0 && std::abs(m.UV(u, 0) - 0.4) < 1e-12;
      const bool on_b = pm.uv_panel[u] == 1 &&
                        dist_to_outline({p.panels[1].outline[3], p.panels[1].outline[0]}, Vec2(m.UV.row(u))) < 1e-12;
      if (on_a) a.push_back(u);
      if (on_b) b.push_back(u);
    }
    REQUIRE(a.size() == b.size());
    CHECK(a.size() >= 3);
    std::set<int> wa, wb;
    for (int u : a) wa.insert(m.uv_to_vertex[u]);
    for (int u : b) wb.insert(m.uv_to_vertex[u]);
    CHECK(wa.size() == a.size());  // one welded vertex per seam position
    CHECK(wa == wb);
    CHECK(static_cast<size_t>(m.V.rows()) == m.UV.rows() - a.size());
    // Reversed seam (start of A's edge meets the end of B's edge): bottoms meet.
    int a_bottom = -1, b_bottom = -1;
    for (int u : a)
      if (m.UV(u, 1) == 0.0) a_bottom = u;
    for (int u : b)
      if (m.UV(u, 1) == 0.0) b_bottom = u;
    REQUIRE(a_bottom >= 0);
    REQUIRE(b_bottom >= 0);
    CHECK(m.uv_to_vertex[a_bottom] == m.uv_to_vertex[b_bottom]);
  }
}

TEST_CASE("pattern: overlapping or bad panels are rejected with a one-line error") {
  auto p = two_squares_pattern(0.5);
  p.panels[1].outline[0].x() = 0.3;  // B now overlaps A
  try {
    sim::mesh_pattern(p, 0.03);
    FAIL("overlap accepted");
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    CHECK(msg.find("overlap") != std::string::npos);
    CHECK(msg.find('\n') == std::string::npos);
  }
  auto q = two_squares_pattern(0.5);
  std::reverse(q.panels[0].outline.begin(), q.panels[0].outline.end());
  CHECK_THROWS_AS(sim::mesh_pattern(q, 0.03), std::runtime_error);  // clockwise
  auto r = two_squares_pattern(0.5);
  r.seams[0].b_edge = 7;
  CHECK_THROWS_AS(sim::mesh_pattern(r, 0.03), std::runtime_error);  // missing edge
  CHECK_THROWS_AS(sim::mesh_pattern(two_squares_pattern(0.5), 0.0), std::runtime_error);
  // Contained panel (no edge crossings) is an overlap too.
  auto s = two_squares_pattern(0.5);
  s.panels[1].outline = {Vec2(0.1, 0.1), Vec2(0.2, 0.1), Vec2(0.2, 0.2), Vec2(0.1, 0.2)};
  s.seams.clear();
  CHECK_THROWS_AS(sim::mesh_pattern(s, 0.03), std::runtime_error);
}

TEST_CASE("pattern: meshing is deterministic") {
  auto a = sim::mesh_pattern(flared_pattern(), 0.02);
  auto b = sim::mesh_pattern(flared_pattern(), 0.02);
  CHECK(a.mesh.UV == b.mesh.UV);
  CHECK(a.mesh.FUV == b.mesh.FUV);
}

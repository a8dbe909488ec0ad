#include "gdsr/sim/pattern.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/union_find.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_no_edge_refinement_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>

namespace sim {

using gdsr::find_root;
using gdsr::Vec2;
using gdsr::Vec3;

namespace {

struct VInfo {
  int id = -1;  // index into the panel's boundary point list, -1 for interior points
};

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vbb = CGAL::Triangulation_vertex_base_with_info_2<VInfo, K>;
using Vb = CGAL::Delaunay_mesh_vertex_base_2<K, Vbb>;
using Fb = CGAL::Delaunay_mesh_face_base_2<K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<CDT>;
using Mesher = CGAL::Delaunay_mesher_no_edge_refinement_2<CDT, Criteria>;

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Closed segments [p0,p1] and [q0,q1] intersect (touching counts).
bool segments_intersect(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1) {
  const double eps = 1e-12;
  auto orient = [&](const Vec2& a, const Vec2& b, const Vec2& c) {
    const double v = cross2(b - a, c - a);
    return v > eps ? 1 : (v < -eps ? -1 : 0);
  };
  auto on_seg = [&](const Vec2& a, const Vec2& b, const Vec2& c) {  // c collinear with ab
    return std::min(a.x(), b.x()) - eps <= c.x() && c.x() <= std::max(a.x(), b.x()) + eps &&
           std::min(a.y(), b.y()) - eps <= c.y() && c.y() <= std::max(a.y(), b.y()) + eps;
  };
  const int o1 = orient(p0, p1, q0), o2 = orient(p0, p1, q1);
  const int o3 = orient(q0, q1, p0), o4 = orient(q0, q1, p1);
  if (o1 != o2 && o3 != o4 && o1 * o2 <= 0 && o3 * o4 <= 0) {
    if (o1 != 0 || o2 != 0) return true;
  }
  if (o1 == 0 && on_seg(p0, p1, q0)) return true;
  if (o2 == 0 && on_seg(p0, p1, q1)) return true;
  if (o3 == 0 && on_seg(q0, q1, p0)) return true;
  if (o4 == 0 && on_seg(q0, q1, p1)) return true;
  return false;
}

bool point_in_polygon(const Vec2& p, const std::vector<Vec2>& poly) {
  bool inside = false;
  const size_t n = poly.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

// Constrained Delaunay triangulation of the outline (pre-split boundary points `bpts`,
// closed polygon) plus interior points `inner`; returns the in-domain triangles with
// indices into [bpts, inner] (boundary first), counter-clockwise, in a canonical order.
std::vector<std::array<int, 3>> cdt_triangles(const std::vector<Vec2>& bpts, const std::vector<Vec2>& inner,
                                              const std::string& name) {
  const int nb = static_cast<int>(bpts.size());
  CDT cdt;
  std::vector<CDT::Vertex_handle> vh(nb);
  for (int k = 0; k < nb; ++k) {
    vh[k] = cdt.insert(CDT::Point(bpts[k].x(), bpts[k].y()));
    vh[k]->info().id = k;
  }
  for (int k = 0; k < nb; ++k) cdt.insert_constraint(vh[k], vh[(k + 1) % nb]);
  if (static_cast<int>(cdt.number_of_vertices()) != nb)
    gdsr::fail("sim/pattern", "panel '" + name + "' has coincident boundary points");
  for (size_t m = 0; m < inner.size(); ++m) {
    auto v = cdt.insert(CDT::Point(inner[m].x(), inner[m].y()));
    if (v->info().id >= 0) gdsr::fail("sim/pattern", "panel '" + name + "': interior point hits another point");
    v->info().id = nb + static_cast<int>(m);
  }
  if (static_cast<int>(cdt.number_of_vertices()) != nb + static_cast<int>(inner.size()))
    gdsr::fail("sim/pattern", "panel '" + name + "': interior point on the boundary");
  // Inside = faces not reachable from the infinite face without crossing a constraint.
  Mesher::mark_convex_hull(cdt);
  std::vector<std::array<int, 3>> tris;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->is_in_domain()) continue;
    std::array<int, 3> t{f->vertex(0)->info().id, f->vertex(1)->info().id, f->vertex(2)->info().id};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    tris.push_back(t);
  }
  std::sort(tris.begin(), tris.end());
  return tris;
}

// Fills the panel with near-equilateral triangles of edge ~h: a hexagonal lattice of
// spacing h clipped to the outline (points closer than 0.6 h to the boundary dropped),
// then a few Jacobi Lloyd-type smoothing passes (each interior point moves to the
// area-weighted centroid of its triangles; re-triangulated each pass). Everything is
// ordered by construction, so the result is identical run to run.
void triangulate_panel(const Panel& panel, const std::vector<Vec2>& bpts, double h, std::vector<Vec2>& pts,
                       std::vector<std::array<int, 3>>& tris) {
  const auto& o = panel.outline;
  const int nb = static_cast<int>(bpts.size());
  Vec2 lo = o[0], hi = o[0];
  for (const auto& c : o) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  auto dist_boundary = [&](const Vec2& q) {
    double best = 1e300;
    for (size_t e = 0; e < o.size(); ++e) {
      const Vec2 a = o[e], b = o[(e + 1) % o.size()];
      const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + t * (b - a) - q).norm());
    }
    return best;
  };
  std::vector<Vec2> inner;
  const double dy = h * std::sqrt(3.0) / 2;
  const int rows = static_cast<int>(std::ceil((hi.y() - lo.y()) / dy));
  const int cols = static_cast<int>(std::ceil((hi.x() - lo.x()) / h)) + 1;
  for (int j = 1; j < rows; ++j)
    for (int i = 0; i <= cols; ++i) {
      const Vec2 q(lo.x() + (i + (j % 2 ? 0.5 : 0.0)) * h, lo.y() + j * dy);
      if (point_in_polygon(q, o) && dist_boundary(q) > 0.6 * h) inner.push_back(q);
    }
  tris = cdt_triangles(bpts, inner, panel.name);
  for (int pass = 0; pass < 6 && !inner.empty(); ++pass) {
    std::vector<Vec2> sum(inner.size(), Vec2::Zero());
    std::vector<double> wsum(inner.size(), 0.0);
    auto at = [&](int id) { return id < nb ? bpts[id] : inner[id - nb]; };
    for (const auto& t : tris) {
      const Vec2 a = at(t[0]), b = at(t[1]), c = at(t[2]);
      const double area = 0.5 * std::abs(cross2(b - a, c - a));
      const Vec2 cen = (a + b + c) / 3.0;
      for (int k = 0; k < 3; ++k)
        if (t[k] >= nb) {
          sum[t[k] - nb] += area * cen;
          wsum[t[k] - nb] += area;
        }
    }
    std::vector<Vec2> moved = inner;
    for (size_t m = 0; m < inner.size(); ++m) {
      if (wsum[m] <= 0) continue;
      const Vec2 q = sum[m] / wsum[m];
      if (point_in_polygon(q, o) && dist_boundary(q) > 0.25 * h) moved[m] = q;
    }
    inner = moved;
    tris = cdt_triangles(bpts, inner, panel.name);
  }
  pts = bpts;
  pts.insert(pts.end(), inner.begin(), inner.end());
}

}  // namespace

double polygon_area(const std::vector<Vec2>& poly) {
  double a = 0;
  for (size_t i = 0; i < poly.size(); ++i) a += cross2(poly[i], poly[(i + 1) % poly.size()]);
  return 0.5 * a;
}

std::vector<Vec2> arc_points(const Vec2& c, double r, double a0, double a1, int n) {
  std::vector<Vec2> pts;
  for (int k = 0; k <= n; ++k) {
    const double a = a0 + (a1 - a0) * k / n;
    pts.push_back(c + r * Vec2(std::cos(a), std::sin(a)));
  }
  return pts;
}

void validate_pattern(const Pattern& p) {
  if (p.panels.empty()) gdsr::fail("sim/pattern", "pattern has no panels");
  for (size_t i = 0; i < p.panels.size(); ++i) {
    const auto& o = p.panels[i].outline;
    const std::string nm = "panel '" + p.panels[i].name + "'";
    if (o.size() < 3) gdsr::fail("sim/pattern", std::string(nm) + " has fewer than 3 corners");
    for (const auto& v : o)
      if (!v.allFinite()) gdsr::fail("sim/pattern", std::string(nm) + " has a non-finite corner");
    if (polygon_area(o) <= 0)
      gdsr::fail("sim/pattern", std::string(nm) + " is degenerate or clockwise (outline must be CCW)");
    const size_t n = o.size();
    for (size_t e = 0; e < n; ++e) {
      if ((o[(e + 1) % n] - o[e]).norm() < 1e-9) gdsr::fail("sim/pattern", std::string(nm) + " has a zero-length edge");
      for (size_t f = e + 2; f < n; ++f) {
        if (e == 0 && f == n - 1) continue;  // adjacent through the closing corner
        if (segments_intersect(o[e], o[(e + 1) % n], o[f], o[(f + 1) % n]))
          gdsr::fail("sim/pattern", std::string(nm) + " intersects itself");
      }
    }
  }
  for (size_t i = 0; i < p.panels.size(); ++i)
    for (size_t j = i + 1; j < p.panels.size(); ++j) {
      const auto& a = p.panels[i].outline;
      const auto& b = p.panels[j].outline;
      bool overlap = point_in_polygon(a[0], b) || point_in_polygon(b[0], a);
      for (size_t e = 0; e < a.size() && !overlap; ++e)
        for (size_t f = 0; f < b.size() && !overlap; ++f)
          overlap = segments_intersect(a[e], a[(e + 1) % a.size()], b[f], b[(f + 1) % b.size()]);
      if (overlap)
        gdsr::fail("sim/pattern",
                   "panels '" + p.panels[i].name + "' and '" + p.panels[j].name + "' overlap in the pattern");
    }
  for (const auto& s : p.seams) {
    const int np = static_cast<int>(p.panels.size());
    if (s.a_panel < 0 || s.a_panel >= np || s.b_panel < 0 || s.b_panel >= np)
      gdsr::fail("sim/pattern", "seam names a missing panel");
    if (s.a_edge < 0 || s.a_edge >= static_cast<int>(p.panels[s.a_panel].outline.size()) || s.b_edge < 0 ||
        s.b_edge >= static_cast<int>(p.panels[s.b_panel].outline.size()))
      gdsr::fail("sim/pattern", "seam names a missing edge");
    if (s.a_panel == s.b_panel && s.a_edge == s.b_edge) gdsr::fail("sim/pattern", "seam joins an edge to itself");
  }
}

PatternMesh mesh_pattern(const Pattern& p, double h) {
  if (!(h > 0) || !std::isfinite(h)) gdsr::fail("sim/pattern", "particle distance must be positive");
  validate_pattern(p);
  const int np = static_cast<int>(p.panels.size());

  // Segments per edge; a seam's two edges share the larger count.
  std::vector<std::vector<int>> nseg(np);
  for (int i = 0; i < np; ++i) {
    const auto& o = p.panels[i].outline;
    for (size_t e = 0; e < o.size(); ++e) {
      const double len = (o[(e + 1) % o.size()] - o[e]).norm();
      nseg[i].push_back(std::max(1, static_cast<int>(std::lround(len / h))));
    }
  }
  for (const auto& s : p.seams) {
    const int n = std::max(nseg[s.a_panel][s.a_edge], nseg[s.b_panel][s.b_edge]);
    nseg[s.a_panel][s.a_edge] = nseg[s.b_panel][s.b_edge] = n;
  }
  long long total_pts = 0;
  for (int i = 0; i < np; ++i) total_pts += std::accumulate(nseg[i].begin(), nseg[i].end(), 0LL);
  if (total_pts > 20000000) gdsr::fail("sim/pattern", "particle distance too small for the pattern size");

  PatternMesh pm;
  std::vector<Vec2> uv;
  std::vector<std::array<int, 3>> fuv;
  // boundary_index[i][e][k]: global UV index of point k (0..n) on edge e of panel i.
  std::vector<std::vector<std::vector<int>>> bindex(np);

  for (int i = 0; i < np; ++i) {
    const auto& o = p.panels[i].outline;
    const int ne = static_cast<int>(o.size());
    std::vector<Vec2> bpts;
    std::vector<int> bedge, bfirst(ne);
    for (int e = 0; e < ne; ++e) {
      bfirst[e] = static_cast<int>(bpts.size());
      const Vec2 a = o[e], b = o[(e + 1) % ne];
      for (int k = 0; k < nseg[i][e]; ++k) {
        bpts.push_back(a + (b - a) * (static_cast<double>(k) / nseg[i][e]));
        bedge.push_back(e);
      }
    }
    const int nb = static_cast<int>(bpts.size());

    std::vector<Vec2> pts;
    std::vector<std::array<int, 3>> tris;
    triangulate_panel(p.panels[i], bpts, h, pts, tris);
    const int base = static_cast<int>(uv.size());
    for (size_t k = 0; k < pts.size(); ++k) {
      uv.push_back(pts[k]);
      pm.uv_panel.push_back(i);
      pm.uv_boundary.push_back(static_cast<int>(k) < nb ? bedge[k] : -1);
    }
    for (auto t : tris) fuv.push_back({base + t[0], base + t[1], base + t[2]});
    std::vector<int> local(nb);
    for (int k = 0; k < nb; ++k) local[k] = base + k;
    bindex[i].resize(ne);
    for (int e = 0; e < ne; ++e) {
      for (int k = 0; k <= nseg[i][e]; ++k) bindex[i][e].push_back(local[(bfirst[e] + k) % nb]);
    }
  }

  // Weld seam copies (union-find on UV vertices).
  const int nuv = static_cast<int>(uv.size());
  std::vector<int> parent(nuv);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& s : p.seams) {
    const auto& A = bindex[s.a_panel][s.a_edge];
    const auto& B = bindex[s.b_panel][s.b_edge];
    const int n = static_cast<int>(A.size()) - 1;
    for (int k = 0; k <= n; ++k) {
      const int ra = find_root(parent, A[k]);
      const int rb = find_root(parent, B[s.reversed ? n - k : k]);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  std::vector<int> welded(nuv, -1);
  int nv = 0;
  pm.mesh.uv_to_vertex.resize(nuv);
  for (int u = 0; u < nuv; ++u) {
    const int r = find_root(parent, u);
    if (welded[r] < 0) welded[r] = nv++;
    pm.mesh.uv_to_vertex[u] = welded[r];
  }

  auto& m = pm.mesh;
  m.UV.resize(nuv, 2);
  for (int u = 0; u < nuv; ++u) m.UV.row(u) = uv[u].transpose();
  m.FUV.resize(static_cast<int>(fuv.size()), 3);
  m.F.resize(static_cast<int>(fuv.size()), 3);
  for (size_t f = 0; f < fuv.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      m.FUV(f, k) = fuv[f][k];
      m.F(f, k) = m.uv_to_vertex[fuv[f][k]];
    }
  for (int f = 0; f < m.F.rows(); ++f)
    if (m.F(f, 0) == m.F(f, 1) || m.F(f, 1) == m.F(f, 2) || m.F(f, 0) == m.F(f, 2))
      gdsr::fail("sim/pattern",
                 "seam welding collapsed a triangle (seam too close to a corner at this particle distance)");
  m.V = gdsr::Points3::Zero(nv, 3);
  return pm;
}

void place_pattern(PatternMesh& pm, const std::function<Vec3(int, const Vec2&)>& place) {
  auto& m = pm.mesh;
  const int nv = static_cast<int>(m.V.rows());
  m.V.setZero();
  std::vector<int> count(nv, 0);
  for (int u = 0; u < m.UV.rows(); ++u) {
    const Vec3 x = place(pm.uv_panel[u], Vec2(m.UV(u, 0), m.UV(u, 1)));
    const int v = m.uv_to_vertex[u];
    m.V.row(v) += x.transpose();
    ++count[v];
  }
  for (int v = 0; v < nv; ++v) m.V.row(v) /= std::max(1, count[v]);
}

}  // namespace sim

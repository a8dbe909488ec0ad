#include "gdsr/geometry/implicit_mesher.hpp"

#include "gdsr/error.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>
#include <vector>

namespace gdsr {

namespace {

// Field values on a regular grid of step h from lo (no value exactly 0).
struct Grid {
  Vec3 lo;
  double h = 0;
  int gx = 0, gy = 0, gz = 0;
  std::vector<double> val;
  long long id(int i, int j, int k) const { return (static_cast<long long>(k) * gy + j) * gx + i; }
  Vec3 pos(long long g) const {
    const int i = static_cast<int>(g % gx), j = static_cast<int>((g / gx) % gy),
              k = static_cast<int>(g / (static_cast<long long>(gx) * gy));
    return Vec3(lo.x() + i * h, lo.y() + j * h, lo.z() + k * h);
  }
};

Grid sample_grid(const std::function<double(const Vec3&)>& field, const Vec3& blo, const Vec3& bhi, double h) {
  Grid G;
  G.lo = blo;
  G.h = h;
  G.gx = static_cast<int>(std::ceil((bhi.x() - blo.x()) / h)) + 1;
  G.gy = static_cast<int>(std::ceil((bhi.y() - blo.y()) / h)) + 1;
  G.gz = static_cast<int>(std::ceil((bhi.z() - blo.z()) / h)) + 1;
  G.val.resize(static_cast<size_t>(G.gx) * G.gy * G.gz);
#pragma omp parallel for schedule(dynamic)
  for (int k = 0; k < G.gz; ++k)
    for (int j = 0; j < G.gy; ++j)
      for (int i = 0; i < G.gx; ++i) {
        double f = field(Vec3(blo.x() + i * h, blo.y() + j * h, blo.z() + k * h));
        if (f == 0) f = 1e-12;  // no vertex exactly on the surface
        G.val[G.id(i, j, k)] = f;
      }
  return G;
}

// Marching tetrahedra (Freudenthal split of each cell): a closed, manifold piecewise-linear
// isosurface, faces wound outward (towards positive values).
void marching_tetrahedra(const Grid& G, std::vector<Vec3>& mv, std::vector<std::array<int, 3>>& mf) {
  const int gx = G.gx, gy = G.gy, gz = G.gz;
  const std::vector<double>& val = G.val;
  auto gid = [&](int i, int j, int k) { return G.id(i, j, k); };
  auto gpos = [&](long long g) { return G.pos(g); };
  std::unordered_map<long long, int> edge_vertex;
  const long long ng = static_cast<long long>(gx) * gy * gz;
  auto crossing = [&](long long a, long long b) {
    if (a > b) std::swap(a, b);
    auto [it, fresh] = edge_vertex.emplace(a * ng + b, static_cast<int>(mv.size()));
    if (fresh) {
      const double fa = val[a], fb = val[b];
      mv.push_back(gpos(a) + (fa / (fa - fb)) * (gpos(b) - gpos(a)));
    }
    return it->second;
  };
  // Freudenthal split of the cube into 6 tetrahedra around the diagonal 0-7 (corner bits x=1, y=2, z=4).
  static const int tets[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7}, {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
  auto emit = [&](int a, int b, int c, const Vec3& out_dir) {
    const Vec3 n = (mv[b] - mv[a]).cross(mv[c] - mv[a]);
    if (n.dot(out_dir) >= 0)
      mf.push_back({a, b, c});
    else
      mf.push_back({a, c, b});
  };
  for (int k = 0; k + 1 < gz; ++k)
    for (int j = 0; j + 1 < gy; ++j)
      for (int i = 0; i + 1 < gx; ++i) {
        long long g[8];
        int neg = 0;
        for (int c = 0; c < 8; ++c) {
          g[c] = gid(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
          neg += val[g[c]] < 0;
        }
        if (neg == 0 || neg == 8) continue;
        for (const auto& t : tets) {
          std::vector<long long> in, out;
          for (int c : t) (val[g[c]] < 0 ? in : out).push_back(g[c]);
          if (in.empty() || out.empty()) continue;
          Vec3 dir = Vec3::Zero();
          for (long long q : out) dir += gpos(q) / out.size();
          for (long long q : in) dir -= gpos(q) / in.size();
          if (in.size() == 1 || out.size() == 1) {
            const long long lone = in.size() == 1 ? in[0] : out[0];
            const auto& rest = in.size() == 1 ? out : in;
            emit(crossing(lone, rest[0]), crossing(lone, rest[1]), crossing(lone, rest[2]), dir);
          } else {
            const int ac = crossing(in[0], out[0]), ad = crossing(in[0], out[1]);
            const int bd = crossing(in[1], out[1]), bc = crossing(in[1], out[0]);
            emit(ac, ad, bd, dir);
            emit(ac, bd, bc, dir);
          }
        }
      }
}

// CGAL isotropic remeshing of the marching-tetrahedra surface to the target edge length.
TriMesh remesh(const std::vector<Vec3>& mv, const std::vector<std::array<int, 3>>& mf, double edge) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using SM = CGAL::Surface_mesh<K::Point_3>;
  SM sm;
  std::vector<SM::Vertex_index> vh;
  vh.reserve(mv.size());
  for (const Vec3& p : mv) vh.push_back(sm.add_vertex(K::Point_3(p.x(), p.y(), p.z())));
  for (const auto& t : mf) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    if (sm.add_face(vh[t[0]], vh[t[1]], vh[t[2]]) == SM::null_face())
      gdsr::fail("implicit_mesher", "marching tetrahedra produced a non-manifold face");
  }
  namespace PMP = CGAL::Polygon_mesh_processing;
  PMP::isotropic_remeshing(faces(sm), edge, sm, CGAL::parameters::number_of_iterations(4));
  sm.collect_garbage();
  if (sm.number_of_faces() < 4) gdsr::fail("implicit_mesher", "remeshing failed");

  const int nv = static_cast<int>(sm.number_of_vertices());
  Points3 V(nv, 3);
  for (auto v : sm.vertices()) {
    const auto& q = sm.point(v);
    V.row(static_cast<int>(v.idx())) << q.x(), q.y(), q.z();
  }
  Faces F(sm.number_of_faces(), 3);
  int k = 0;
  for (auto f : sm.faces()) {
    int j = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) F(k, j++) = static_cast<int>(v.idx());
    ++k;
  }
  return TriMesh{V, F};
}

// Newton steps onto the zero set of the field (central-difference gradient), each step at
// most a quarter of the edge length.
void project_to_zero_set(const std::function<double(const Vec3&)>& field, Points3& V, double edge) {
  const int nv = static_cast<int>(V.rows());
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    Vec3 p = V.row(i);
    for (int it = 0; it < 3; ++it) {
      const double f = field(p), e = 1e-4;
      Vec3 g;
      for (int c = 0; c < 3; ++c) {
        Vec3 d = Vec3::Zero();
        d[c] = e;
        g[c] = (field(p + d) - field(p - d)) / (2 * e);
      }
      const double gg = g.squaredNorm();
      if (!(gg > 1e-8)) break;
      Vec3 step = g * (f / gg);
      if (step.norm() > 0.25 * edge) step *= 0.25 * edge / step.norm();
      p -= step;
    }
    V.row(i) = p.transpose();
  }
}

// Outward orientation: positive signed volume.
void orient_outward(const Points3& V, Faces& F) {
  double vol = 0;
  for (int f = 0; f < F.rows(); ++f) vol += Vec3(V.row(F(f, 0))).dot(Vec3(V.row(F(f, 1))).cross(Vec3(V.row(F(f, 2)))));
  if (vol < 0) F.col(1).swap(F.col(2));
}

}  // namespace

TriMesh mesh_implicit(const std::function<double(const Vec3&)>& field, Vec3 blo, Vec3 bhi, double h, double edge) {
  blo -= Vec3::Constant(2 * h);
  bhi += Vec3::Constant(2 * h);
  const Grid G = sample_grid(field, blo, bhi, h);
  std::vector<Vec3> mv;
  std::vector<std::array<int, 3>> mf;
  marching_tetrahedra(G, mv, mf);
  if (mf.size() < 4) gdsr::fail("implicit_mesher", "marching tetrahedra found no surface");
  TriMesh m = remesh(mv, mf, edge);
  project_to_zero_set(field, m.V, edge);
  orient_outward(m.V, m.F);
  return m;
}

}  // namespace gdsr

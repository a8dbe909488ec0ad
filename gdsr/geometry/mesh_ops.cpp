#include "gdsr/geometry/mesh_ops.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/union_find.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>

namespace gdsr {
namespace {

Vec3 row3(const Points3& V, int i) { return V.row(i).transpose(); }

Vec3 normalized_eps(const Vec3& a, double eps) { return a / std::max(a.norm(), eps); }

// Each face edge as (min, max, face, opposite vertex), sorted by the edge.
struct HalfEdge {
  int a, b, face, opp;
};
std::vector<HalfEdge> sorted_half_edges(const Faces& F) {
  std::vector<HalfEdge> h;
  h.reserve(static_cast<size_t>(F.rows()) * 3);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      int i = F(f, k), j = F(f, (k + 1) % 3), o = F(f, (k + 2) % 3);
      h.push_back({std::min(i, j), std::max(i, j), f, o});
    }
  std::sort(h.begin(), h.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.a != y.a ? x.a < y.a : x.b != y.b ? x.b < y.b : x.face < y.face;
  });
  return h;
}

Pairs to_pairs(const std::vector<std::array<int, 2>>& v) {
  Pairs P(static_cast<long>(v.size()), 2);
  for (size_t i = 0; i < v.size(); ++i) P.row(static_cast<long>(i)) << v[i][0], v[i][1];
  return P;
}

}  // namespace

Points3 face_normals(const Points3& V, const Faces& F) {
  Points3 N(F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f) {
    Vec3 n = (row3(V, F(f, 1)) - row3(V, F(f, 0))).cross(row3(V, F(f, 2)) - row3(V, F(f, 0)));
    const double len = n.norm();
    N.row(f) = (len > 0 ? Vec3(n / len) : Vec3::Zero()).transpose();
  }
  return N;
}

Points3 vertex_normals(const Points3& V, const Faces& F) {
  Points3 N = Points3::Zero(V.rows(), 3);
  for (int f = 0; f < F.rows(); ++f) {
    Vec3 n = (row3(V, F(f, 1)) - row3(V, F(f, 0))).cross(row3(V, F(f, 2)) - row3(V, F(f, 0)));
    for (int k = 0; k < 3; ++k) N.row(F(f, k)) += n.transpose();
  }
  for (int i = 0; i < N.rows(); ++i) {
    double len = N.row(i).norm();
    if (len > 0) N.row(i) /= len;
  }
  return N;
}

Pairs unique_edges(const Faces& F) {
  std::vector<std::array<int, 2>> e;
  e.reserve(static_cast<size_t>(F.rows()) * 3);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      int i = F(f, k), j = F(f, (k + 1) % 3);
      e.push_back({std::min(i, j), std::max(i, j)});
    }
  std::sort(e.begin(), e.end());
  e.erase(std::unique(e.begin(), e.end()), e.end());
  return to_pairs(e);
}

Csr build_csr(std::vector<std::vector<int>>&& lists) {
  Csr c;
  c.offsets.assign(lists.size() + 1, 0);
  for (size_t v = 0; v < lists.size(); ++v) c.offsets[v + 1] = c.offsets[v] + static_cast<int>(lists[v].size());
  c.items.reserve(static_cast<size_t>(c.offsets.back()));
  for (auto& l : lists) c.items.insert(c.items.end(), l.begin(), l.end());
  return c;
}

Csr vertex_edges(const std::vector<std::array<int, 2>>& ends, int num_vertices) {
  std::vector<std::vector<int>> lists(static_cast<size_t>(num_vertices));
  for (int e = 0; e < static_cast<int>(ends.size()); ++e)
    for (int v : ends[e]) {
      if (v < 0 || v >= num_vertices) gdsr::fail("vertex_edges", "edge end out of range");
      lists[v].push_back(e);
    }
  return build_csr(std::move(lists));
}

Csr vertex_faces(const Faces& F, int num_vertices) {
  std::vector<std::vector<int>> lists(static_cast<size_t>(num_vertices));
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      int v = F(f, k);
      if (v < 0 || v >= num_vertices) gdsr::fail("vertex_faces", "face index out of range");
      if (lists[v].empty() || lists[v].back() != f) lists[v].push_back(f);
    }
  return build_csr(std::move(lists));
}

Csr vertex_neighbours(const Faces& F, int num_vertices) {
  std::vector<std::vector<int>> lists(static_cast<size_t>(num_vertices));
  Pairs E = unique_edges(F);
  for (int e = 0; e < E.rows(); ++e) {
    if (E(e, 1) >= num_vertices || E(e, 0) < 0) gdsr::fail("vertex_neighbours", "face index out of range");
    lists[E(e, 0)].push_back(E(e, 1));
    lists[E(e, 1)].push_back(E(e, 0));
  }
  for (auto& l : lists) std::sort(l.begin(), l.end());
  return build_csr(std::move(lists));
}

Pairs ring2_pairs(const Faces& F, int num_vertices) {
  const Csr nb = vertex_neighbours(F, num_vertices);
  std::vector<std::array<int, 2>> out;
  std::vector<int> mark(static_cast<size_t>(num_vertices), -1);  // last vertex that visited
  std::vector<int> cand;
  for (int v = 0; v < num_vertices; ++v) {
    mark[v] = v;
    for (int a = nb.offsets[v]; a < nb.offsets[v + 1]; ++a) mark[nb.items[a]] = v;
    cand.clear();
    for (int a = nb.offsets[v]; a < nb.offsets[v + 1]; ++a) {
      int u = nb.items[a];
      for (int b = nb.offsets[u]; b < nb.offsets[u + 1]; ++b) {
        int w = nb.items[b];
        if (mark[w] != v && w > v) {
          mark[w] = v;
          cand.push_back(w);
        }
      }
    }
    std::sort(cand.begin(), cand.end());
    for (int w : cand) out.push_back({v, w});
  }
  return to_pairs(out);
}

FacePairs adjacent_face_pairs(const Faces& F) {
  const std::vector<HalfEdge> h = sorted_half_edges(F);
  std::vector<std::array<int, 2>> faces, edge, opp;
  for (size_t s = 0; s < h.size();) {
    size_t t = s;
    while (t < h.size() && h[t].a == h[s].a && h[t].b == h[s].b) ++t;
    for (size_t k = s; k + 1 < t; ++k) {
      faces.push_back({h[k].face, h[k + 1].face});
      edge.push_back({h[s].a, h[s].b});
      opp.push_back({h[k].opp, h[k + 1].opp});
    }
    s = t;
  }
  return FacePairs{to_pairs(faces), to_pairs(edge), to_pairs(opp)};
}

std::vector<int> boundary_vertices(const Faces& F) {
  const std::vector<HalfEdge> h = sorted_half_edges(F);
  std::vector<int> out;
  for (size_t s = 0; s < h.size();) {
    size_t t = s;
    while (t < h.size() && h[t].a == h[s].a && h[t].b == h[s].b) ++t;
    if (t - s == 1) {
      out.push_back(h[s].a);
      out.push_back(h[s].b);
    }
    s = t;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

double mean_edge_length(const Points3& V, const Faces& F) {
  const Pairs E = unique_edges(F);
  if (E.rows() == 0) return 0.0;
  double s = 0;
  for (int e = 0; e < E.rows(); ++e) s += (V.row(E(e, 0)) - V.row(E(e, 1))).norm();
  return s / static_cast<double>(E.rows());
}

Frames triangle_frames(const Points3& V, const Faces& F, double eps) {
  Frames out(F.rows(), 9);
  for (int f = 0; f < F.rows(); ++f) {
    const Vec3 v0 = row3(V, F(f, 0)), v1 = row3(V, F(f, 1)), v2 = row3(V, F(f, 2));
    const Vec3 a = v2 - v1, b = v0 - v1;
    const double L2 = a.squaredNorm() + b.squaredNorm();  // the triangle's size, squared
    if (!(L2 > 0)) {  // collapsed to a point: the zero frame
      out.row(f).setZero();
      continue;
    }
    const Vec3 y = normalized_eps(a, eps * std::sqrt(L2));
    const Vec3 z = normalized_eps(a.cross(b), eps * L2);
    const Vec3 x = y.cross(z);
    out.row(f) << x.transpose(), y.transpose(), z.transpose();
  }
  return out;
}

Eigen::VectorXd dihedral_angles(const Points3& V, const Faces& F, const FacePairs& pairs) {
  const Points3 N = face_normals(V, F);
  Eigen::VectorXd a(pairs.size());
  for (int p = 0; p < pairs.size(); ++p) {
    const Vec3 n0 = N.row(pairs.faces(p, 0)).transpose(), n1 = N.row(pairs.faces(p, 1)).transpose();
    a(p) = std::atan2(n0.cross(n1).norm(), n0.dot(n1));
  }
  return a;
}

std::vector<std::vector<int>> vertices_by_layer(const std::vector<int>& layer, int num_vertices) {
  if (layer.empty()) {
    std::vector<int> all(static_cast<size_t>(num_vertices));
    for (int i = 0; i < num_vertices; ++i) all[i] = i;
    return {all};
  }
  if (static_cast<int>(layer.size()) != num_vertices)
    gdsr::fail("vertices_by_layer",
               std::to_string(layer.size()) + " layer ids for " + std::to_string(num_vertices) + " vertices");
  const int n = *std::max_element(layer.begin(), layer.end()) + 1;
  std::vector<std::vector<int>> out(static_cast<size_t>(std::max(n, 1)));
  for (int i = 0; i < num_vertices; ++i) {
    if (layer[i] < 0) gdsr::fail("vertices_by_layer", "negative layer id");
    out[layer[i]].push_back(i);
  }
  return out;
}

std::vector<std::vector<int>> faces_by_layer(const std::vector<int>& layer, const Faces& F) {
  if (layer.empty()) {
    std::vector<int> all(static_cast<size_t>(F.rows()));
    for (int f = 0; f < F.rows(); ++f) all[f] = f;
    return {all};
  }
  const int n = *std::max_element(layer.begin(), layer.end()) + 1;
  std::vector<std::vector<int>> out(static_cast<size_t>(std::max(n, 1)));
  for (int f = 0; f < F.rows(); ++f) {
    const int v = F(f, 0);
    if (v < 0 || v >= static_cast<int>(layer.size()) || layer[v] < 0)
      gdsr::fail("faces_by_layer", "face " + std::to_string(f) + " has no valid layer");
    out[layer[v]].push_back(f);
  }
  return out;
}

namespace {
// Midpoint index per undirected edge of a face set; new indices start at `first`.
std::map<std::pair<int, int>, int> midpoint_ids(const Faces& F, int first) {
  std::map<std::pair<int, int>, int> ids;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      int i = F(f, k), j = F(f, (k + 1) % 3);
      auto key = std::make_pair(std::min(i, j), std::max(i, j));
      if (!ids.count(key)) {
        const int id = first + static_cast<int>(ids.size());
        ids.emplace(key, id);
      }
    }
  return ids;
}

int mid(const std::map<std::pair<int, int>, int>& ids, int i, int j) {
  return ids.at(std::make_pair(std::min(i, j), std::max(i, j)));
}

// Face f with corner ids c0..c2 and midpoints m01, m12, m20 -> 4 faces at 4f.
void write_four(Faces& out, int f, int c0, int c1, int c2, int m01, int m12, int m20) {
  out.row(4 * f + 0) << c0, m01, m20;
  out.row(4 * f + 1) << m01, c1, m12;
  out.row(4 * f + 2) << m20, m12, c2;
  out.row(4 * f + 3) << m01, m12, m20;
}
}  // namespace

GarmentMesh subdivide_midpoint(const GarmentMesh& g) {
  const int nv = static_cast<int>(g.V.rows()), nu = static_cast<int>(g.UV.rows());
  const auto vid = midpoint_ids(g.F, nv);
  const auto uid = midpoint_ids(g.FUV, nu);
  GarmentMesh s;
  s.V.resize(nv + static_cast<long>(vid.size()), 3);
  s.V.topRows(nv) = g.V;
  for (const auto& [e, id] : vid) s.V.row(id) = 0.5 * (g.V.row(e.first) + g.V.row(e.second));
  s.UV.resize(nu + static_cast<long>(uid.size()), 2);
  s.UV.topRows(nu) = g.UV;
  for (const auto& [e, id] : uid) s.UV.row(id) = 0.5 * (g.UV.row(e.first) + g.UV.row(e.second));
  s.F.resize(4 * g.F.rows(), 3);
  s.FUV.resize(4 * g.F.rows(), 3);
  s.uv_to_vertex.assign(s.UV.rows(), -1);
  for (int i = 0; i < nu && i < static_cast<int>(g.uv_to_vertex.size()); ++i) s.uv_to_vertex[i] = g.uv_to_vertex[i];
  for (int f = 0; f < g.F.rows(); ++f) {
    const int a = g.F(f, 0), b = g.F(f, 1), c = g.F(f, 2);
    const int p = g.FUV(f, 0), q = g.FUV(f, 1), r = g.FUV(f, 2);
    const int mab = mid(vid, a, b), mbc = mid(vid, b, c), mca = mid(vid, c, a);
    const int mpq = mid(uid, p, q), mqr = mid(uid, q, r), mrp = mid(uid, r, p);
    write_four(s.F, f, a, b, c, mab, mbc, mca);
    write_four(s.FUV, f, p, q, r, mpq, mqr, mrp);
    s.uv_to_vertex[mpq] = mab;
    s.uv_to_vertex[mqr] = mbc;
    s.uv_to_vertex[mrp] = mca;
  }
  if (!g.layer.empty()) {
    s.layer.assign(s.V.rows(), 0);
    for (int i = 0; i < nv; ++i) s.layer[i] = g.layer[i];
    for (const auto& [e, id] : vid) s.layer[id] = g.layer[e.first];
  }
  return s;
}

std::vector<int> uv_islands(const GarmentMesh& g) {
  const int nuv = static_cast<int>(g.UV.rows());
  std::vector<int> parent(nuv);
  for (int i = 0; i < nuv; ++i) parent[i] = i;
  for (int f = 0; f < g.FUV.rows(); ++f)
    for (int k = 1; k < 3; ++k) parent[find_root(parent, g.FUV(f, k))] = find_root(parent, g.FUV(f, 0));
  std::vector<double> min_x(nuv, std::numeric_limits<double>::infinity());
  for (int i = 0; i < nuv; ++i) {
    const int r = find_root(parent, i);
    min_x[r] = std::min(min_x[r], g.UV(i, 0));
  }
  std::vector<int> roots;
  for (int i = 0; i < nuv; ++i)
    if (parent[i] == i) roots.push_back(i);
  std::sort(roots.begin(), roots.end(),
            [&](int a, int b) { return min_x[a] < min_x[b] || (min_x[a] == min_x[b] && a < b); });
  std::vector<int> index(nuv, -1);
  for (size_t k = 0; k < roots.size(); ++k) index[roots[k]] = static_cast<int>(k);
  std::vector<int> island(nuv);
  for (int i = 0; i < nuv; ++i) island[i] = index[find_root(parent, i)];
  return island;
}

}  // namespace gdsr

#include "infer/collision.hpp"

#include "gdsr/error.hpp"

#include "gdsr/body/body_query.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>

namespace gdsr {

namespace {

// A subset of rows of a Points3 as a nanoflann point cloud.
struct SubsetCloud {
  const Points3* P = nullptr;
  std::vector<int> rows;
  size_t kdtree_get_point_count() const { return rows.size(); }
  double kdtree_get_pt(size_t i, size_t d) const { return (*P)(rows[i], static_cast<int>(d)); }
  template <class BBox> bool kdtree_get_bbox(BBox&) const { return false; }
};
using SubsetTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, SubsetCloud>, SubsetCloud, 3, uint32_t>;

// HR vertices grouped by their nearest LR vertex (CSR).
struct Groups {
  std::vector<int> offsets, items;
};
Groups group_hr(const std::vector<int>& nearest, int num_lr) {
  Groups g;
  g.offsets.assign(static_cast<size_t>(num_lr) + 1, 0);
  for (int i : nearest) ++g.offsets[i + 1];
  for (int i = 0; i < num_lr; ++i) g.offsets[i + 1] += g.offsets[i];
  g.items.resize(nearest.size());
  std::vector<int> fill(g.offsets.begin(), g.offsets.end() - 1);
  for (size_t k = 0; k < nearest.size(); ++k) g.items[fill[nearest[k]]++] = static_cast<int>(k);
  return g;
}

// Appends the HR vertices of LR vertex i to `rows`.
void append_group(const Groups& g, int i, std::vector<int>& rows) {
  rows.insert(rows.end(), g.items.begin() + g.offsets[i], g.items.begin() + g.offsets[i + 1]);
}

// Moves row v of G along n out of the plane (p, n) to offset sigma; true when it moved.
bool push_out_of_plane(int v, const Vec3& p, const Vec3& n, double sigma, Points3& G) {
  const Vec3 x = G.row(v).transpose();
  const double m = sigma - (x - p).dot(n);
  if (!(m > 0)) return false;
  G.row(v) = (x + m * n).transpose();
  return true;
}

// Moves the HR vertices of LR vertex i out of the plane (p, n) to offset sigma; returns moved count.
int push_group(const Groups& g, int i, const Vec3& p, const Vec3& n, double sigma, Points3& G) {
  int moved = 0;
  for (int k = g.offsets[i]; k < g.offsets[i + 1]; ++k) moved += push_out_of_plane(g.items[k], p, n, sigma, G);
  return moved;
}

// Moves each HR vertex in `rows` out of its own closest body point's tangent plane to offset
// sigma (one query for all of them); returns the moved count.
int push_own_planes(const std::vector<int>& rows, const BodyQueryFn& body, double sigma, Points3& G) {
  Points3 q(static_cast<Eigen::Index>(rows.size()), 3), b, n;
  for (size_t k = 0; k < rows.size(); ++k) q.row(static_cast<Eigen::Index>(k)) = G.row(rows[k]);
  body(q, b, n);
  if (b.rows() != q.rows() || n.rows() != q.rows())
    gdsr::fail("collision", "body query returned the wrong number of rows");
  int moved = 0;
  for (size_t k = 0; k < rows.size(); ++k) {
    const Eigen::Index r = static_cast<Eigen::Index>(k);
    moved += push_out_of_plane(rows[k], b.row(r).transpose(), n.row(r).transpose(), sigma, G);
  }
  return moved;
}

// The LR garment's faces of the layers below L (all three vertices of layer < L), with only
// the vertices they use.
TriMesh inner_layers(const Points3& C, const Faces& F, const std::vector<int>& layer, int L) {
  std::vector<int> index(C.rows(), -1), rows, faces;
  for (int f = 0; f < F.rows(); ++f) {
    if (layer[F(f, 0)] >= L || layer[F(f, 1)] >= L || layer[F(f, 2)] >= L) continue;
    faces.push_back(f);
    for (int c = 0; c < 3; ++c)
      if (index[F(f, c)] < 0) {
        index[F(f, c)] = static_cast<int>(rows.size());
        rows.push_back(F(f, c));
      }
  }
  TriMesh m;
  m.V.resize(static_cast<Eigen::Index>(rows.size()), 3);
  for (size_t r = 0; r < rows.size(); ++r) m.V.row(static_cast<Eigen::Index>(r)) = C.row(rows[r]);
  m.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t k = 0; k < faces.size(); ++k)
    for (int c = 0; c < 3; ++c) m.F(static_cast<Eigen::Index>(k), c) = index[F(faces[k], c)];
  return m;
}

// Moves each HR vertex in `rows` out of the tangent plane of its own closest point on the
// inner layers (smooth normal) to offset sigma_l. Skipped: vertices farther than gamma from
// them, and vertices beside the inner layers' open edge rather than over them (offset along
// the surface above sigma_l), which a plane at the edge would drag sideways. Returns the
// moved count.
int push_over_layer(const std::vector<int>& rows, const TriMesh& inner, const CollisionConfig& cfg, Points3& G) {
  if (inner.F.rows() == 0) return 0;
  Points3 q(static_cast<Eigen::Index>(rows.size()), 3);
  for (size_t k = 0; k < rows.size(); ++k) q.row(static_cast<Eigen::Index>(k)) = G.row(rows[k]);
  const ClosestPoints c = BodyQuery(inner).closest(q, true, cfg.gamma);
  int moved = 0;
  for (size_t k = 0; k < rows.size(); ++k) {
    const Eigen::Index r = static_cast<Eigen::Index>(k);
    if (c.face(r) < 0) continue;
    const Vec3 p = c.point.row(r).transpose(), n = c.normal.row(r).transpose();
    const Vec3 d = q.row(r).transpose() - p;
    if ((d - d.dot(n) * n).norm() > cfg.sigma_l) continue;
    moved += push_out_of_plane(rows[k], p, n, cfg.sigma_l, G);
  }
  return moved;
}

// The first of `keys` in sim_params that holds a plausible offset (a number of metres in
// (0, 0.1)), else `fallback`.
double offset_from(const nlohmann::json& sim_params, std::initializer_list<const char*> keys, double fallback) {
  for (const char* key : keys) {
    const auto it = sim_params.find(key);
    if (it != sim_params.end() && it->is_number() && it->get<double>() > 0 && it->get<double>() < 0.1)
      return it->get<double>();
  }
  return fallback;
}

}  // namespace

double body_offset_for(const nlohmann::json& sim_params, double given) {
  if (given >= 0) return given;
  return offset_from(sim_params, {"thickness_m"}, CollisionConfig{}.sigma_b);
}

double layer_offset_for(const nlohmann::json& sim_params, double given) {
  if (given >= 0) return given;
  return offset_from(sim_params, {"layer_gap_m", "thickness_m"}, CollisionConfig{}.sigma_l);
}

BodyQueryFn body_query_fn(const BodyQuery& body) {
  return [&body](const Points3& q, Points3& closest, Points3& normal) {
    ClosestPoints c = body.closest(q, true);
    closest = std::move(c.point);
    normal = std::move(c.normal);
  };
}

CollisionStats resolve_collisions(const CollisionConfig& cfg, const CollisionInput& in, Points3& G) {
  if (in.C_hat == nullptr || in.hr_nearest_lr == nullptr)
    gdsr::fail("collision", "C_hat and hr_nearest_lr are required");
  const Points3& C = *in.C_hat;
  const int nl = static_cast<int>(C.rows());
  const std::vector<int>& nearest = *in.hr_nearest_lr;
  if (static_cast<int64_t>(nearest.size()) != G.rows())
    gdsr::fail("collision", "hr_nearest_lr has " + std::to_string(nearest.size()) + " entries for " +
                                std::to_string(G.rows()) + " HR vertices");
  for (int i : nearest)
    if (i < 0 || i >= nl) gdsr::fail("collision", "hr_nearest_lr entry " + std::to_string(i) + " out of range");
  CollisionStats st;
  const bool do_body = cfg.body && in.body != nullptr && *in.body;
  const bool multi_layer = in.lr_layer != nullptr && !in.lr_layer->empty() &&
                           *std::max_element(in.lr_layer->begin(), in.lr_layer->end()) > 0;
  const bool do_layers = cfg.layers && multi_layer;
  if (!do_body && !do_layers) return st;
  const Groups groups = group_hr(nearest, nl);

  if (do_body) {
    Points3 b(nl, 3), n(nl, 3);
    (*in.body)(C, b, n);
    if (b.rows() != nl || n.rows() != nl) gdsr::fail("collision", "body query returned the wrong number of rows");
    st.body_queried = true;
    std::vector<int> candidates;  // HR vertices of colliding LR vertices (hr_planes)
    for (int i = 0; i < nl; ++i) {
      const Vec3 p = b.row(i).transpose(), nb = n.row(i).transpose();
      if (cfg.sigma_b - (C.row(i).transpose() - p).dot(nb) > 0) {
        ++st.lr_body;
        if (cfg.hr_planes)
          append_group(groups, i, candidates);
        else
          st.hr_body += push_group(groups, i, p, nb, cfg.sigma_b, G);
      }
    }
    if (!candidates.empty()) st.hr_body += push_own_planes(candidates, *in.body, cfg.sigma_b, G);
    st.hr_queried = static_cast<int>(candidates.size());
  }

  if (do_layers) {
    const std::vector<int>& layer = *in.lr_layer;
    if (static_cast<int>(layer.size()) != nl) gdsr::fail("collision", "lr_layer size differs from the LR vertex count");
    if (in.lr_F == nullptr) gdsr::fail("collision", "lr_F is required for layer collisions");
    st.layers_checked = true;
    const Points3 N = vertex_normals(C, *in.lr_F);
    const int top = *std::max_element(layer.begin(), layer.end());
    for (int L = 1; L <= top; ++L) {
      SubsetCloud cloud;
      cloud.P = &C;
      for (int i = 0; i < nl; ++i)
        if (layer[i] < L) cloud.rows.push_back(i);
      if (cloud.rows.empty()) continue;
      SubsetTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
      std::vector<int> candidates;  // HR vertices of colliding LR vertices of layer L (hr_planes)
      for (int e = 0; e < nl; ++e) {
        if (layer[e] != L) continue;
        uint32_t idx = 0;
        double d2 = 0;
        const double q[3] = {C(e, 0), C(e, 1), C(e, 2)};
        if (tree.knnSearch(q, 1, &idx, &d2) < 1) continue;
        const int i = cloud.rows[idx];
        const Vec3 ci = C.row(i).transpose(), ni = N.row(i).transpose();
        if (d2 < cfg.gamma * cfg.gamma && cfg.sigma_l - (C.row(e).transpose() - ci).dot(ni) > 0) {
          ++st.lr_layer;
          if (cfg.hr_planes)
            append_group(groups, e, candidates);
          else
            st.hr_layer += push_group(groups, e, ci, ni, cfg.sigma_l, G);
        }
      }
      if (!candidates.empty()) st.hr_layer += push_over_layer(candidates, inner_layers(C, *in.lr_F, layer, L), cfg, G);
      st.hr_layer_queried += static_cast<int>(candidates.size());
    }
  }
  return st;
}

}  // namespace gdsr

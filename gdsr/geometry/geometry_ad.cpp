#include "gdsr/geometry/geometry_ad.hpp"

#include "gdsr/error.hpp"

#include "autograd/ops_elementwise.hpp"
#include "autograd/ops_index.hpp"
#include "autograd/ops_reduce.hpp"
#include "autograd/ops_shape.hpp"
#include "autograd/ops_vec3.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gdsr {

namespace {

void check_faces(const Faces& F, int num_vertices, const char* what) {
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) < 0 || F(f, k) >= num_vertices)
        gdsr::fail("geometry_ad", std::string(what) + " index out of range at face " + std::to_string(f));
}

template <class T> void check_positions(const ag::Tensor<T>& X, const MeshTopology& t, const char* op) {
  if (X.dim() != 2 || X.cols() != 3 || X.rows() != t.num_vertices)
    gdsr::fail("geometry_ad", std::string(op) + ": positions must be [" + std::to_string(t.num_vertices) +
                                  " x 3], got " + ag::shape_str(X.shape()));
}

// A constant column [N x 1] holding one entry of each face's Dm^-1.
template <class T> ag::Tensor<T> dm_column(const MeshTopology& t, int entry) {
  const int64_t n = static_cast<int64_t>(t.strain_faces.size());
  std::vector<T> v(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) v[i] = static_cast<T>(t.dm_inv[4 * i + entry]);
  return ag::Tensor<T>::from({n, 1}, std::move(v));
}

}  // namespace

MeshTopology make_topology(const Faces& F, int num_vertices, const Points2& UV, const Faces& FUV, double normal_eps,
                           const Points3* rest3d) {
  if (num_vertices < 0) gdsr::fail("geometry_ad", "negative vertex count");
  check_faces(F, num_vertices, "face");
  MeshTopology t;
  t.num_vertices = num_vertices;
  t.num_faces = static_cast<int>(F.rows());
  const int nf = t.num_faces;
  t.c0.resize(nf);
  t.c1.resize(nf);
  t.c2.resize(nf);
  t.corner_vertex.resize(3 * static_cast<size_t>(nf));
  t.corner_face.resize(3 * static_cast<size_t>(nf));
  std::vector<char> used(static_cast<size_t>(num_vertices), 0);
  for (int f = 0; f < nf; ++f) {
    t.c0[f] = F(f, 0);
    t.c1[f] = F(f, 1);
    t.c2[f] = F(f, 2);
    for (int k = 0; k < 3; ++k) {
      t.corner_vertex[3 * f + k] = F(f, k);
      t.corner_face[3 * f + k] = f;
      used[F(f, k)] = 1;
    }
  }
  for (int v = 0; v < num_vertices; ++v)
    if (used[v]) t.smooth_vertices.push_back(v);

  const FacePairs pairs = adjacent_face_pairs(F);
  for (int p = 0; p < pairs.size(); ++p) {
    t.pair_f0.push_back(pairs.faces(p, 0));
    t.pair_f1.push_back(pairs.faces(p, 1));
  }

  double area_sum = 0;
  int area_count = 0;
  std::vector<double> area2(static_cast<size_t>(nf), -1.0);  // doubled rest area, -1 unknown
  if (UV.rows() > 0) {
    if (FUV.rows() != F.rows())
      gdsr::fail("geometry_ad", "FUV has " + std::to_string(FUV.rows()) + " faces, F has " + std::to_string(F.rows()));
    check_faces(FUV, static_cast<int>(UV.rows()), "UV face");
    for (int f = 0; f < nf; ++f) {
      const Vec2 a = UV.row(FUV(f, 0)).transpose(), b = UV.row(FUV(f, 1)).transpose(),
                 c = UV.row(FUV(f, 2)).transpose();
      const Vec2 e1 = b - a, e2 = c - a;
      const double det = e1.x() * e2.y() - e2.x() * e1.y();
      const double lmax2 = std::max({e1.squaredNorm(), e2.squaredNorm(), (c - b).squaredNorm()});
      if (!(std::abs(det) > 1e-8 * lmax2) || !std::isfinite(det)) {
        ++t.num_degenerate_uv;
        continue;
      }
      area2[f] = std::abs(det);
      area_sum += std::abs(det);
      ++area_count;
      t.strain_faces.push_back(f);
      t.s0.push_back(F(f, 0));
      t.s1.push_back(F(f, 1));
      t.s2.push_back(F(f, 2));
      // Dm = [[e1.x, e2.x], [e1.y, e2.y]]; inverse row-major.
      t.dm_inv.push_back(e2.y() / det);
      t.dm_inv.push_back(-e2.x() / det);
      t.dm_inv.push_back(-e1.y() / det);
      t.dm_inv.push_back(e1.x() / det);
    }
  } else if (rest3d != nullptr && rest3d->rows() == num_vertices) {
    for (int f = 0; f < nf; ++f) {
      const Vec3 a = rest3d->row(F(f, 0)).transpose(), b = rest3d->row(F(f, 1)).transpose(),
                 c = rest3d->row(F(f, 2)).transpose();
      const double d = (b - a).cross(c - a).norm();
      if (d > 0 && std::isfinite(d)) {
        area2[f] = d;
        area_sum += d;
        ++area_count;
      }
    }
  }
  if (normal_eps > 0)
    t.normal_eps = normal_eps;
  else
    t.normal_eps = area_count > 0 ? 1e-6 * area_sum / area_count : 1e-12;
  // Without any rest shape the mean doubled area is taken as normal_eps / 1e-6 (1e-6 m^2 when
  // that is the absolute fallback).
  const double mean_area2 = area_count > 0 ? area_sum / area_count : t.normal_eps / 1e-6;
  t.dihedral_floor.resize(static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f)
    t.dihedral_floor[f] = kDihedralFade * (area2[f] > 1e-8 * mean_area2 ? area2[f] : mean_area2);
  return t;
}

MeshTopology make_topology(const GarmentMesh& g, double normal_eps) {
  return make_topology(g.F, static_cast<int>(g.V.rows()), g.UV, g.FUV, normal_eps, &g.V);
}

template <class T> ag::Tensor<T> face_cross(const ag::Tensor<T>& X, const MeshTopology& t) {
  check_positions(X, t, "face_cross");
  const ag::Tensor<T> x0 = ag::index_select_rows(X, t.c0);
  const ag::Tensor<T> e1 = ag::sub(ag::index_select_rows(X, t.c1), x0);
  const ag::Tensor<T> e2 = ag::sub(ag::index_select_rows(X, t.c2), x0);
  return ag::cross3(e1, e2);
}

template <class T> ag::Tensor<T> face_normals(const ag::Tensor<T>& X, const MeshTopology& t) {
  return ag::normalize_rows(face_cross(X, t), static_cast<T>(t.normal_eps));
}

template <class T> ag::Tensor<T> vertex_normals(const ag::Tensor<T>& X, const MeshTopology& t) {
  const ag::Tensor<T> c = ag::index_select_rows(face_cross(X, t), t.corner_face);
  const ag::Tensor<T> sum = ag::scatter_add_rows(c, t.corner_vertex, t.num_vertices);
  return ag::normalize_rows(sum, static_cast<T>(t.normal_eps));
}

template <class T> UVGradient<T> uv_gradient(const ag::Tensor<T>& X, const MeshTopology& t) {
  check_positions(X, t, "uv_gradient");
  if (t.strain_faces.empty()) gdsr::fail("geometry_ad", "uv_gradient: no face with a valid UV rest shape");
  const ag::Tensor<T> x0 = ag::index_select_rows(X, t.s0);
  const ag::Tensor<T> e1 = ag::sub(ag::index_select_rows(X, t.s1), x0);
  const ag::Tensor<T> e2 = ag::sub(ag::index_select_rows(X, t.s2), x0);
  UVGradient<T> g;
  g.Fu = ag::add(ag::mul(e1, dm_column<T>(t, 0)), ag::mul(e2, dm_column<T>(t, 2)));
  g.Fv = ag::add(ag::mul(e1, dm_column<T>(t, 1)), ag::mul(e2, dm_column<T>(t, 3)));
  return g;
}

template <class T> ag::Tensor<T> strain_measures(const ag::Tensor<T>& X, const MeshTopology& t) {
  const UVGradient<T> g = uv_gradient(X, t);
  const T eps = static_cast<T>(kShearEps);
  const ag::Tensor<T> shear = ag::dot_rows(ag::normalize_rows(g.Fu, eps), ag::normalize_rows(g.Fv, eps));
  return ag::concat_cols<T>({ag::norm_rows(g.Fu), ag::norm_rows(g.Fv), shear});
}

template <class T> ag::Tensor<T> smoothness_residual(const ag::Tensor<T>& X, const MeshTopology& t) {
  check_positions(X, t, "smoothness_residual");
  const ag::Tensor<T> sum3 =
      ag::add(ag::add(ag::index_select_rows(X, t.c0), ag::index_select_rows(X, t.c1)), ag::index_select_rows(X, t.c2));
  const ag::Tensor<T> centroid = ag::mul_scalar(sum3, static_cast<T>(1.0 / 3.0));
  const ag::Tensor<T> mean =
      ag::scatter_mean_rows(ag::index_select_rows(centroid, t.corner_face), t.corner_vertex, t.num_vertices);
  ag::Tensor<T> r = ag::sub(X, mean);
  if (static_cast<int>(t.smooth_vertices.size()) == t.num_vertices) return r;
  // Isolated vertices: residual 0 (mask them out).
  std::vector<T> m(static_cast<size_t>(t.num_vertices), T(0));
  for (int64_t v : t.smooth_vertices) m[v] = T(1);
  return ag::mul(r, ag::Tensor<T>::from({t.num_vertices, 1}, std::move(m)));
}

template <class T> ag::Tensor<T> smoothness(const ag::Tensor<T>& X, const MeshTopology& t, const ag::Index* vertices) {
  ag::Tensor<T> r = smoothness_residual(X, t);
  double count = t.num_vertices;
  if (vertices != nullptr) {
    if (vertices->empty()) gdsr::fail("geometry_ad", "smoothness: empty vertex subset");
    r = ag::index_select_rows(r, *vertices);
    count = static_cast<double>(vertices->size());
  }
  if (count <= 0) gdsr::fail("geometry_ad", "smoothness: mesh without vertices");
  return ag::mul_scalar(ag::sum(ag::square(r)), static_cast<T>(1.0 / count));
}

template <class T> DihedralTerms<T> dihedral_terms(const ag::Tensor<T>& X, const MeshTopology& t) {
  if (t.pair_f0.empty()) gdsr::fail("geometry_ad", "dihedral_angles: mesh has no adjacent face pairs");
  const ag::Tensor<T> c = face_cross(X, t);
  const ag::Tensor<T> n = ag::normalize_rows(c, static_cast<T>(t.normal_eps));
  const ag::Tensor<T> n0 = ag::index_select_rows(n, t.pair_f0);
  const ag::Tensor<T> n1 = ag::index_select_rows(n, t.pair_f1);
  DihedralTerms<T> d;
  d.angle = ag::atan2(ag::norm_rows(ag::cross3(n0, n1)), ag::dot_rows(n0, n1));
  std::vector<T> floor(t.dihedral_floor.begin(), t.dihedral_floor.end());
  const ag::Tensor<T> s = ag::clamp(ag::div(ag::norm_rows(c), ag::Tensor<T>::from({t.num_faces, 1}, std::move(floor))),
                                    T(0), T(1));
  d.weight = ag::mul(ag::index_select_rows(s, t.pair_f0), ag::index_select_rows(s, t.pair_f1));
  return d;
}

template <class T> ag::Tensor<T> dihedral_angles(const ag::Tensor<T>& X, const MeshTopology& t) {
  return dihedral_terms(X, t).angle;
}

template <class T> ag::Tensor<T> to_tensor(const Points3& P) { return ag::Tensor<T>::from_eigen(P.cast<T>()); }

template <class T> Points3 to_points(const ag::Tensor<T>& X) {
  if (X.dim() != 2 || X.cols() != 3)
    gdsr::fail("geometry_ad", "to_points needs an [N x 3] tensor, got " + ag::shape_str(X.shape()));
  return X.mat().template cast<double>();
}

#define GDSR_GEOMETRY_AD_INSTANTIATE(T)                                                              \
  template ag::Tensor<T> face_cross<T>(const ag::Tensor<T>&, const MeshTopology&);                   \
  template ag::Tensor<T> face_normals<T>(const ag::Tensor<T>&, const MeshTopology&);                 \
  template ag::Tensor<T> vertex_normals<T>(const ag::Tensor<T>&, const MeshTopology&);               \
  template UVGradient<T> uv_gradient<T>(const ag::Tensor<T>&, const MeshTopology&);                  \
  template ag::Tensor<T> strain_measures<T>(const ag::Tensor<T>&, const MeshTopology&);              \
  template ag::Tensor<T> smoothness_residual<T>(const ag::Tensor<T>&, const MeshTopology&);          \
  template ag::Tensor<T> smoothness<T>(const ag::Tensor<T>&, const MeshTopology&, const ag::Index*); \
  template ag::Tensor<T> dihedral_angles<T>(const ag::Tensor<T>&, const MeshTopology&);              \
  template DihedralTerms<T> dihedral_terms<T>(const ag::Tensor<T>&, const MeshTopology&);            \
  template ag::Tensor<T> to_tensor<T>(const Points3&);                                               \
  template Points3 to_points<T>(const ag::Tensor<T>&);

GDSR_GEOMETRY_AD_INSTANTIATE(float)
GDSR_GEOMETRY_AD_INSTANTIATE(double)

}  // namespace gdsr

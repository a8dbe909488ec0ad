// Differentiable geometry on vertex position tensors X [V x 3] (metres): face and vertex
// normals, the per-face UV deformation gradient F = Ds Dm^-1 (columns F_u, F_v), the
// smoothness residual and dihedral angles. Everything integer or rest-shape related is
// precomputed once in a MeshTopology; the functions only build graph ops on X.
//
// Numerical choices (all finite at degenerate input, no NaN):
// - Normals: cross / max(|cross|, normal_eps) (PyTorch's F.normalize). normal_eps defaults
//   to 1e-6 x the mean doubled UV triangle area, i.e. relative to the mesh's own scale, so
//   metres and millimetres behave alike (the reference uses an absolute 1e-6 m^2). A
//   zero-area face has normal 0 and a gradient bounded by |d cross| / normal_eps.
// - UV rest shape: faces whose UV triangle is (near) degenerate, |det Dm| <= 1e-8 * (longest
//   UV edge)^2, have no Dm^-1; they are skipped by the strain term (counted in
//   num_degenerate_uv) instead of producing infinite F.
// - Dihedral angle atan2(|n0 x n1|, n0 . n1) is in [0, pi]; at exactly 0 (flat) and pi
//   (folded) |n0 x n1| = 0 where the norm's subgradient is 0, so the angle's gradient
//   there is 0 (the unsigned angle has a kink at 0 and pi).
// Valid range: edge lengths between ~1e-150 and ~1e150 (float32: 1e-19 and 1e19) in any
// unit, where their squares and cross products stay normal floats; tested from 1e-3 to 1e3.
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/geometry/mesh.hpp"

#include <vector>

namespace gdsr {

struct MeshTopology {
  int num_vertices = 0;
  int num_faces = 0;
  ag::Index c0, c1, c2;        // F: corner k of each face
  ag::Index corner_vertex;     // 3F: vertex of corner (f, k) at 3f + k
  ag::Index corner_face;       // 3F: f at 3f + k
  ag::Index pair_f0, pair_f1;  // faces sharing an edge (dihedral pairs)
  ag::Index smooth_vertices;   // vertices with at least one face (ascending)
  // Strain: faces with a valid UV rest shape, their corners and Dm^-1 (row-major 2 x 2,
  // 1 / metres). F = [x1 - x0, x2 - x0] Dm^-1 with Dm = [uv1 - uv0, uv2 - uv0].
  ag::Index strain_faces, s0, s1, s2;
  std::vector<double> dm_inv;  // 4 per strain face
  int num_degenerate_uv = 0;
  double normal_eps = 1e-12;  // metres^2 (see header comment)
  // Per face: kDihedralFade x its doubled rest area (metres^2; the mesh's mean for a face
  // whose rest shape is degenerate), where the dihedral weight starts to fade (dihedral_terms).
  std::vector<double> dihedral_floor;
};

// Faces compressed below this fraction of their rest area fade out of the dihedral loss.
constexpr double kDihedralFade = 1e-2;
// Floor of |F_u| and |F_v| in the shear measure (dimensionless: a stretch of 1 is rest).
constexpr double kShearEps = 1e-2;

// F: faces x 3 into X's rows (num_vertices rows). UV / FUV: flat rest shape (metres); face f
// is FUV.row(f) in UV. Pass UV empty (0 rows) for no strain data. normal_eps <= 0: automatic
// (1e-6 x mean doubled UV area, or x mean doubled 3-D area of `rest3d` when no UV is given;
// 1e-12 if neither is available). Throws on bad indices or mismatched face counts.
MeshTopology make_topology(const Faces& F, int num_vertices, const Points2& UV, const Faces& FUV,
                           double normal_eps = -1, const Points3* rest3d = nullptr);
// Whole garment: F / V / UV / FUV of the GarmentMesh.
MeshTopology make_topology(const GarmentMesh& g, double normal_eps = -1);

// Unnormalised face cross products (x1 - x0) x (x2 - x0), [F x 3] (length = 2 x area).
template <class T> ag::Tensor<T> face_cross(const ag::Tensor<T>& X, const MeshTopology& t);
// Unit face normals [F x 3].
template <class T> ag::Tensor<T> face_normals(const ag::Tensor<T>& X, const MeshTopology& t);
// Area-weighted unit vertex normals [V x 3] (sum of adjacent face crosses, normalised).
template <class T> ag::Tensor<T> vertex_normals(const ag::Tensor<T>& X, const MeshTopology& t);

// Columns of F per strain face: Fu, Fv [S x 3] (dimensionless: 3-D metres per UV metre).
template <class T> struct UVGradient { ag::Tensor<T> Fu, Fv; };
template <class T> UVGradient<T> uv_gradient(const ag::Tensor<T>& X, const MeshTopology& t);
// Strain measures per strain face, [S x 3]: |F_u|, |F_v|, normalize(F_u) . normalize(F_v)
// with normalize(a) = a / max(|a|, kShearEps). The reference uses eps 1e-6, which lets a face
// collapsed along u or v (coincident vertices: F_v = 0) have a shear gradient of 1e6 |Dm^-1|,
// 1e5 x every other vertex's gradient of the whole coarse loss; 1e-2 bounds it by ~2 |Dm^-1|
// / 1e-2 and changes nothing on faces stretched to at least 1% of their rest size along u and
// v (all of cloth's healthy range).
template <class T> ag::Tensor<T> strain_measures(const ag::Tensor<T>& X, const MeshTopology& t);

// Smoothness residual [V x 3]: x_v - mean of the centroids of v's faces (0 rows for
// isolated vertices).
template <class T> ag::Tensor<T> smoothness_residual(const ag::Tensor<T>& X, const MeshTopology& t);
// sum over `vertices` of |residual|^2 / |vertices| -> [1 x 1] (metres^2). vertices null:
// all vertices, divided by num_vertices (the reference's normalisation).
template <class T>
ag::Tensor<T> smoothness(const ag::Tensor<T>& X, const MeshTopology& t, const ag::Index* vertices = nullptr);

// Dihedral angle per adjacent face pair, [P x 1], radians in [0, pi].
template <class T> ag::Tensor<T> dihedral_angles(const ag::Tensor<T>& X, const MeshTopology& t);
// The angles and, per pair, weight = s0 s1 [P x 1] with s = min(1, |cross| / dihedral_floor)
// per face: exactly 1 (gradient 0) for pairs of faces with at least kDihedralFade of their
// rest area, falling linearly with the area to 0 as either face degenerates. The angle's own
// gradient is 1 / height on a sliver (1e9 at 1e-9 m high) and is undefined at zero area;
// weight * angle has a gradient bounded by ~ (1 + pi) edge / dihedral_floor ~ (1 + pi) /
// (kDihedralFade x rest height), i.e. ~400 x a healthy face's angle gradient, whatever the
// sliver (the former |n0| |n1| weighting, which fades only below normal_eps, still let a
// 1e-9 m sliver's gradient reach 7e4 x every other vertex's gradient of the coarse loss).
template <class T> struct DihedralTerms {
  ag::Tensor<T> angle, weight;
};
template <class T> DihedralTerms<T> dihedral_terms(const ag::Tensor<T>& X, const MeshTopology& t);

// Points3 (N x 3, metres) -> tensor [N x 3] (a leaf without grad) and back.
template <class T> ag::Tensor<T> to_tensor(const Points3& P);
template <class T> Points3 to_points(const ag::Tensor<T>& X);

}  // namespace gdsr

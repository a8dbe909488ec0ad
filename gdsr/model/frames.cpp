#include "gdsr/model/frames.hpp"

#include "gdsr/error.hpp"

#include "autograd/autograd.hpp"

#include <limits>
#include <stdexcept>

namespace gdsr {

namespace {
ag::Index face_column(const Faces& F, const ag::Index& faces, int k) {
  ag::Index out(faces.size());
  for (size_t i = 0; i < faces.size(); ++i) {
    const int64_t f = faces[i];
    if (f < 0 || f >= F.rows()) gdsr::fail("model_geometry", "face index out of range");
    out[i] = F(f, k);
  }
  return out;
}
}  // namespace

namespace {
// a / max(|a|, floor) per row, floor [n x 1] differentiable: the two branches of PyTorch's
// F.normalize with a per-row eps. A row with |a| = floor = 0 (a triangle collapsed to a point)
// gives 0.
template <class T> ag::Tensor<T> normalize_rows_floor(const ag::Tensor<T>& a, const ag::Tensor<T>& floor) {
  const ag::Tensor<T> n = ag::norm_rows(a);
  const int64_t R = n.rows();
  std::vector<T> use_norm(static_cast<size_t>(R)), point(static_cast<size_t>(R));
  for (int64_t r = 0; r < R; ++r) {
    use_norm[r] = n.data()[r] > floor.data()[r] ? T(1) : T(0);
    point[r] = n.data()[r] == T(0) && floor.data()[r] == T(0) ? T(1) : T(0);
  }
  const ag::Tensor<T> m = ag::Tensor<T>::from({R, 1}, std::move(use_norm));
  const ag::Tensor<T> d = ag::add(ag::add(ag::mul(m, n), ag::mul(ag::add_scalar(ag::neg(m), T(1)), floor)),
                                  ag::Tensor<T>::from({R, 1}, std::move(point)));
  return ag::div(a, d);
}
}  // namespace

template <class T>
ag::Tensor<T> triangle_frames_ad(const ag::Tensor<T>& X, const Faces& F, const ag::Index& faces, T eps) {
  if (!(eps > T(0))) gdsr::fail("triangle_frames_ad", "eps must be > 0 (a fraction of the triangle's size)");
  const ag::Tensor<T> v0 = ag::index_select_rows(X, face_column(F, faces, 0));
  const ag::Tensor<T> v1 = ag::index_select_rows(X, face_column(F, faces, 1));
  const ag::Tensor<T> v2 = ag::index_select_rows(X, face_column(F, faces, 2));
  const ag::Tensor<T> a = ag::sub(v2, v1), b = ag::sub(v0, v1);
  // The triangle's own size L = sqrt(|a|^2 + |b|^2): eps is relative to it (L for y, L^2 for
  // the normal), so mm and m meshes get the same frames.
  const ag::Tensor<T> L = ag::norm_rows(ag::concat_cols<T>({a, b}));
  const ag::Tensor<T> y = normalize_rows_floor(a, ag::mul_scalar(L, eps));
  const ag::Tensor<T> z = normalize_rows_floor(ag::cross3(a, b), ag::mul_scalar(ag::square(L), eps));
  // y, z are unit and orthogonal (or shrunk on degenerate faces), so y x z needs no third
  // normalisation; one fewer 1/eps factor in the gradient of degenerate faces.
  const ag::Tensor<T> x = ag::cross3(y, z);
  return ag::concat_cols<T>({x, y, z});
}

template <class T> ag::Tensor<T> local_to_world(const ag::Tensor<T>& r, const ag::Tensor<T>& frames) {
  ag::Tensor<T> out;
  for (int k = 0; k < 3; ++k) {
    const ag::Tensor<T> term = ag::mul(ag::slice_cols(r, k, k + 1), ag::slice_cols(frames, 3 * k, 3 * k + 3));
    out = k == 0 ? term : ag::add(out, term);
  }
  return out;
}

template <class T> ag::Tensor<T> vertex_normals_ad(const ag::Tensor<T>& X, const Faces& F, T eps) {
  if (!(eps > T(0))) gdsr::fail("vertex_normals_ad", "eps must be > 0 (a fraction of the vertex's area)");
  ag::Index all(F.rows());
  for (int64_t f = 0; f < F.rows(); ++f) all[f] = f;
  const ag::Tensor<T> v0 = ag::index_select_rows(X, face_column(F, all, 0));
  const ag::Tensor<T> v1 = ag::index_select_rows(X, face_column(F, all, 1));
  const ag::Tensor<T> v2 = ag::index_select_rows(X, face_column(F, all, 2));
  const ag::Tensor<T> c = ag::cross3(ag::sub(v1, v0), ag::sub(v2, v0));
  // Each face's cross goes to its three corners.
  ag::Index corner_face(3 * F.rows()), corner_vertex(3 * F.rows());
  for (int64_t f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) corner_face[3 * f + k] = f, corner_vertex[3 * f + k] = F(f, k);
  const ag::Tensor<T> sum = ag::scatter_add_rows(ag::index_select_rows(c, corner_face), corner_vertex, X.rows());
  // The floor scales with the vertex's own area (an absolute eps would shrink the normals of
  // a mesh in small units). Formed as unit(sum) * min(1, |sum| / floor): on every vertex above
  // the floor the factor is exactly 1 with gradient 0, so the normals and their gradients are
  // bit-identical to a plain normalisation there.
  const ag::Tensor<T> area = ag::scatter_add_rows(ag::index_select_rows(ag::norm_rows(c), corner_face), corner_vertex,
                                                  X.rows());
  const ag::Tensor<T> floor = ag::mul_scalar(area, eps);
  std::vector<T> point(static_cast<size_t>(X.rows()));  // floor 0 (no area at all): divide by 1
  for (int64_t r = 0; r < X.rows(); ++r) point[r] = floor.data()[r] == T(0) ? T(1) : T(0);
  const ag::Tensor<T> shrink =
      ag::clamp(ag::div(ag::norm_rows(sum), ag::add(floor, ag::Tensor<T>::from({X.rows(), 1}, std::move(point)))),
                T(0), T(1));
  return ag::mul(ag::normalize_rows(sum, std::numeric_limits<T>::min()), shrink);
}

#define INSTANTIATE(T)                                                                                   \
  template ag::Tensor<T> triangle_frames_ad<T>(const ag::Tensor<T>&, const Faces&, const ag::Index&, T); \
  template ag::Tensor<T> local_to_world<T>(const ag::Tensor<T>&, const ag::Tensor<T>&);                  \
  template ag::Tensor<T> vertex_normals_ad<T>(const ag::Tensor<T>&, const Faces&, T);
INSTANTIATE(float)
INSTANTIATE(double)
#undef INSTANTIATE

}  // namespace gdsr

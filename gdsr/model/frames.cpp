#include "gdsr/model/frames.hpp"

#include "gdsr/error.hpp"

#include "autograd/autograd.hpp"

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

template <class T>
ag::Tensor<T> triangle_frames_ad(const ag::Tensor<T>& X, const Faces& F, const ag::Index& faces, T eps) {
  const ag::Tensor<T> v0 = ag::index_select_rows(X, face_column(F, faces, 0));
  const ag::Tensor<T> v1 = ag::index_select_rows(X, face_column(F, faces, 1));
  const ag::Tensor<T> v2 = ag::index_select_rows(X, face_column(F, faces, 2));
  const ag::Tensor<T> a = ag::sub(v2, v1);
  const ag::Tensor<T> y = ag::normalize_rows(a, eps);
  const ag::Tensor<T> z = ag::normalize_rows(ag::cross3(a, ag::sub(v0, v1)), eps);
  const ag::Tensor<T> x = ag::normalize_rows(ag::cross3(y, z), eps);
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
  return ag::normalize_rows(sum, eps);
}

#define INSTANTIATE(T)                                                                                   \
  template ag::Tensor<T> triangle_frames_ad<T>(const ag::Tensor<T>&, const Faces&, const ag::Index&, T); \
  template ag::Tensor<T> local_to_world<T>(const ag::Tensor<T>&, const ag::Tensor<T>&);                  \
  template ag::Tensor<T> vertex_normals_ad<T>(const ag::Tensor<T>&, const Faces&, T);
INSTANTIATE(float)
INSTANTIATE(double)
#undef INSTANTIATE

}  // namespace gdsr

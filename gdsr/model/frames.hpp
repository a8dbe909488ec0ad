// Differentiable geometry used by the GDSR network itself (features, E, A): local triangle
// frames, local -> world mapping and vertex normals, built from autograd ops on a position
// tensor X [V x 3] (metres) so gradients reach positions and parameters. Valid range as
// geometry_ad.hpp's: edge lengths between ~1e-150 and ~1e150 (float32: 1e-19 and 1e19), where
// squared lengths and cross products stay normal floats; tested from 1e-5 to 1e3.
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/geometry/geometry_ad.hpp"  // to_tensor / to_points
#include "gdsr/geometry/mesh.hpp"

namespace gdsr {

// Local frame of the faces `faces` (indices into F) of X: rows (x, y, z) flattened to
// [n x 9] with y = normalize(v2 - v1, eps L), z = normalize((v2 - v1) x (v0 - v1), eps L^2),
// x = y x z; normalize(a, e) = a / max(|a|, e), L = sqrt(|v2 - v1|^2 + |v0 - v1|^2) the
// triangle's own size. eps > 0 is dimensionless (the reference uses an absolute 1e-6, which
// shrinks the normal of a triangle with 1 mm edges to 0.89): frames are invariant under
// scaling X, and exact unit frames for every triangle whose shortest-edge / area ratios stay
// above eps. Degenerate faces (zero area, coincident vertices) get a shrunk frame with a
// gradient bounded by ~2 / (eps L); a face collapsed to a point gets the zero frame. The
// models use eps = 1e-2 (ModelConfig::frame_eps): A decodes its residual r in the frames of
// the predicted C_hat, so a sliver of C_hat passes |r| / height to the loss gradient; with
// eps 1e-6 one sliver got 2.5e5 x the healthy vertices' median, with 1e-2 30 x for
// residuals of ~1 cm on 5 cm triangles (test_frames.cpp).
template <class T>
ag::Tensor<T> triangle_frames_ad(const ag::Tensor<T>& X, const Faces& F, const ag::Index& faces, T eps);

// World vector of local coordinates r [N x 3] in frames [N x 9] (rows x, y, z):
// r0 x + r1 y + r2 z -> [N x 3].
template <class T> ag::Tensor<T> local_to_world(const ag::Tensor<T>& r, const ag::Tensor<T>& frames);

// Area-weighted unit vertex normals [V x 3]: sum over adjacent faces of c = (v1 - v0) x
// (v2 - v0), divided by max(|sum|, eps * sum |c|). eps > 0 is dimensionless (relative to the
// vertex's own doubled area, so normals do not change when X is scaled): unit normals except
// where the adjacent faces fold onto each other to within eps; 0 at an isolated vertex or one
// whose faces all have zero area.
template <class T> ag::Tensor<T> vertex_normals_ad(const ag::Tensor<T>& X, const Faces& F, T eps = T(1e-6));

}  // namespace gdsr

// Embree 3 queries against one triangle mesh (a body frame): batched closest points with
// normal and signed distance, and batched ray casts. Queries run with OpenMP over the batch.
//
// Closest point: exact in double precision on the mesh's double vertices (Embree's float BVH
// only culls, with a conservative radius).
// Normal (`normal`): by default the smooth body normal, i.e. the barycentric interpolation
// of angle-weighted vertex normals at the closest point, normalised (continuous over the
// surface: this is n_b of the GDSR features). With smooth_normals = false it is the
// pseudonormal of the closest feature (face normal inside a face, normalised sum of the two
// face normals on an edge, angle-weighted normal at a vertex).
// Signed distance: |q - closest| with the sign of (q - closest) . pseudonormal
// (Baerentzen & Aanaes), which is exact for closed, consistently oriented meshes, also when
// the closest point is on an edge or a vertex. Positive outside (the normal side).
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <functional>
#include <limits>
#include <memory>

namespace gdsr {

struct ClosestPoints {
  Points3 point;          // N x 3 closest surface point, metres
  Points3 normal;         // N x 3 unit normal there (see header comment), 0 when face < 0
  Eigen::VectorXd sdist;  // N signed distance, metres, > 0 outside; +inf when face < 0
  Eigen::VectorXi face;   // N triangle index; -1 when no surface within max_distance
  Points3 bary;           // N x 3 barycentric weights of the triangle's vertices F(face, 0..2)
};

struct RayHits {
  Eigen::VectorXd t;     // N hit distance along the ray (in units of |direction|); +inf on a miss
  Eigen::VectorXi face;  // N triangle index, -1 on a miss
  Points2 uv;            // N x 2 Embree barycentrics: hit = (1-u-v) V0 + u V1 + v V2
};

class BodyQuery {
 public:
  enum class Update { Rebuild, Refit };  // how update() rebuilds the BVH

  // Throws gdsr::Error for an empty mesh, non-finite vertices or bad face indices.
  explicit BodyQuery(const TriMesh& mesh, Update mode = Update::Rebuild);
  ~BodyQuery();
  BodyQuery(BodyQuery&&) noexcept;
  BodyQuery& operator=(BodyQuery&&) noexcept;
  BodyQuery(const BodyQuery&) = delete;
  BodyQuery& operator=(const BodyQuery&) = delete;

  // New vertex positions (vertices x 3, same topology); re-commits the Embree scene.
  void update(const Points3& V);

  // Closest points for queries Q (N x 3, metres). Points farther than max_distance from the
  // mesh get face = -1 (a speed knob; default: no limit). Throws on non-finite queries.
  ClosestPoints closest(const Points3& Q, bool smooth_normals = true,
                        double max_distance = std::numeric_limits<double>::infinity()) const;

  // Whether a triangle f with accept(f) has a point within `radius` metres of q (exact in double
  // precision; Embree's float BVH only culls). accept may be called for some triangles farther
  // away, and not at all once one is found.
  bool any_face_within(const Vec3& q, double radius, const std::function<bool(int face)>& accept) const;
  // Ray casts: origins and directions N x 3 (directions need not be unit; t is in units of
  // the direction's length), hits with t in [tmin, tmax]. Throws on non-finite input or
  // zero directions.
  RayHits intersect(const Points3& origins, const Points3& dirs, double tmin = 0.0,
                    double tmax = std::numeric_limits<double>::infinity()) const;

  const TriMesh& mesh() const;
  const Points3& face_normals() const;    // F x 3 unit (0 for degenerate triangles)
  const Points3& vertex_normals() const;  // V x 3 unit, angle-weighted

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gdsr

// Closest points on a moving triangle surface (the body) for the cloth solver and the
// metrics: a uniform grid over the triangles' bounding boxes, valid for every linear blend
// between two poses, queried within a search radius. Exact within the radius (the cells and
// the face boxes only prune; tests/gdsr/sim/test_cloth_collision.cpp holds it to a search over
// every face, bit for bit), deterministic (ties go to the lower face id).
// Positions in metres.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

namespace sim {

struct SurfaceHit {
  int face = -1;                           // -1: nothing within the radius
  gdsr::Vec3 bary = gdsr::Vec3::Zero();    // barycentric of the closest point in `face`
  gdsr::Vec3 point = gdsr::Vec3::Zero();   // closest surface point
  gdsr::Vec3 normal = gdsr::Vec3::Zero();  // outward unit normal there (face normals averaged over ties)
  double signed_distance = 0;              // > 0 outside, < 0 inside (metres)
};

// The faces one query point must test: those whose boxes, in the pose queried, lie within the
// search radius, ascending, each with its closest point once a query has needed it. One set
// serves several queries at the same point, pose and radius (the solver's: the closest face, then
// the closest of another body part), each face's exact test made once.
struct SurfaceCandidates {
  struct Face {
    int face;
    double gap2;          // squared distance from the point to the face's box, m^2
    bool tested = false;  // bary, point and d2 below are set
    gdsr::Vec3 bary, point;
    double d2;  // squared distance to the closest point, m^2
  };
  gdsr::Vec3 x = gdsr::Vec3::Zero();
  double radius = 0;
  std::vector<Face> faces;
};

class SurfaceGrid {
 public:
  // Grid for triangles F over poses V0 and V1 (and any blend between them); cell in metres.
  void build(const gdsr::Faces& F, const gdsr::Points3& V0, const gdsr::Points3& V1, double cell);
  // Closest point on the surface with vertex positions V (same topology, a pose covered by
  // build) to x, searching within `radius` metres; only faces for which `accept(face)` holds
  // when it is given.
  SurfaceHit closest(const gdsr::Vec3& x, const gdsr::Points3& V, double radius,
                     const std::function<bool(int)>& accept = {}) const;
  // The same query in two steps: the candidates for x in pose V within radius, then the closest
  // among them (accepted by `accept`, if given); closest(c, V, accept) after candidates(x, V,
  // radius, c) gives closest(x, V, radius, accept) bit for bit, as often as it is asked.
  void candidates(const gdsr::Vec3& x, const gdsr::Points3& V, double radius, SurfaceCandidates& out) const;
  SurfaceHit closest(SurfaceCandidates& c, const gdsr::Points3& V, const std::function<bool(int)>& accept = {}) const;
  bool empty() const { return faces_.empty(); }

 private:
  const gdsr::Faces* F_ = nullptr;
  double cell_ = 0;
  gdsr::Vec3 origin_ = gdsr::Vec3::Zero();  // cell (0, 0, 0) starts here
  // The cells the face boxes cover, a dense block from cell index lo_ with dims_ cells per
  // axis, stored compressed: cell c holds faces_[start_[c] .. start_[c + 1]), ascending.
  Eigen::Vector3i lo_ = Eigen::Vector3i::Zero(), dims_ = Eigen::Vector3i::Zero();
  std::vector<int> start_, faces_;
};

}  // namespace sim

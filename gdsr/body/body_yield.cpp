#include "gdsr/body/body_yield.hpp"

#include "gdsr/body/body_query.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

namespace gdsr {
namespace {

// Past a hit, the next cast starts this far along the ray: beyond float round-off at body
// scale (1e-7 m), so a hit on an edge is not counted again on the face across it.
constexpr double kRayStep = 1e-5;
// Vertices whose surface ended within 2% of the gap of the other side count as given way: a
// vertex that ends exactly `gap` away would be found buried again by round-off.
constexpr double kGapTolerance = 0.02;

struct Crossing {
  double t;  // m along the ray
  int sign;  // +1: the ray leaves the surface's inside there (face normal along the ray), -1: enters
  int face;
};

// Every crossing of the rays O + t D (D unit) with the surface for t in [0, tmax], nearest first.
std::vector<std::vector<Crossing>> crossings(const BodyQuery& q, const Points3& O, const Points3& D, double tmax) {
  const Eigen::Index n = O.rows();
  std::vector<std::vector<Crossing>> out(n);
  std::vector<double> t0(n, 0.0);
  std::vector<Eigen::Index> active(n);
  std::iota(active.begin(), active.end(), Eigen::Index{0});
  const Points3& FN = q.face_normals();
  for (int round = 0; round < 256 && !active.empty(); ++round) {
    const auto m = static_cast<Eigen::Index>(active.size());
    Points3 Ob(m, 3), Db(m, 3);
    for (Eigen::Index k = 0; k < m; ++k) {
      const Eigen::Index i = active[k];
      Db.row(k) = D.row(i);
      Ob.row(k) = O.row(i) + D.row(i) * t0[i];
    }
    const RayHits h = q.intersect(Ob, Db, 0.0, tmax);
    std::vector<Eigen::Index> next;
    for (Eigen::Index k = 0; k < m; ++k) {
      const Eigen::Index i = active[k];
      if (h.face(k) < 0) continue;
      const double t = t0[i] + h.t(k);
      if (t > tmax) continue;
      out[i].push_back({t, FN.row(h.face(k)).dot(D.row(i)) > 0 ? 1 : -1, h.face(k)});
      t0[i] = t + kRayStep;
      next.push_back(i);
    }
    active.swap(next);
  }
  return out;
}

int winding(const std::vector<Crossing>& to_infinity) {
  int w = 0;
  for (const Crossing& c : to_infinity) w += c.sign;
  return w;
}

// The winding number at V + offset * normal per vertex, along the normal and along a direction
// tilted off it (a ray through an edge or a vertex may miscount; the two rarely both do), the
// smaller of the two.
std::vector<int> offset_winding(const BodyQuery& q, const Points3& V, const Points3& N, double offset) {
  const Eigen::Index n = V.rows();
  Points3 O = V + offset * N, D2(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 nv = N.row(i).transpose();
    D2.row(i) = (nv + 0.3 * nv.unitOrthogonal()).normalized().transpose();
  }
  const double far = std::numeric_limits<double>::infinity();
  const auto a = crossings(q, O, N, far), b = crossings(q, O, D2, far);
  std::vector<int> w(n);
  for (Eigen::Index i = 0; i < n; ++i) w[i] = std::min(winding(a[i]), winding(b[i]));
  return w;
}

struct Dent {
  Eigen::Index vertex;
  double depth;  // m, along the vertex's inward normal
};

// How far each vertex gives way (along its inward normal, m) for the dents: a dent of depth d
// at vertex i takes the vertices of its part within falloff + d of it along, linearly less with
// distance and with the angle between their normals (none on the far side of a limb), so flesh
// dents rather than one vertex sinking into a pit. The deepest dent reaching a vertex wins.
template <class SamePart> Eigen::VectorXd dent_depths(const Points3& V, const Points3& N,
                                                      const std::vector<Dent>& dents, const SamePart& same_part,
                                                      double falloff) {
  Eigen::VectorXd depth = Eigen::VectorXd::Zero(V.rows());
  for (const Dent& d : dents) {
    const double radius = falloff + d.depth;
    for (Eigen::Index j = 0; j < V.rows(); ++j) {
      const double along = N.row(j).dot(N.row(d.vertex));
      if (along <= 0 || !same_part(d.vertex, j)) continue;
      const double dist = (V.row(j) - V.row(d.vertex)).norm();
      if (dist < radius) depth(j) = std::max(depth(j), d.depth * (1 - dist / radius) * along);
    }
  }
  return depth;
}

Points3 unit_vertex_normals(const Points3& V, const Faces& F) {
  Points3 N = vertex_normals(V, F);
  for (Eigen::Index i = 0; i < N.rows(); ++i)
    if (N.row(i).squaredNorm() == 0) N.row(i) = Vec3::UnitY().transpose();  // isolated: never buried
  return N;
}

}  // namespace

std::vector<char> buried_vertices(const Faces& F, const Points3& V, double offset) {
  const BodyQuery q(TriMesh{V, F});
  const std::vector<int> w = offset_winding(q, V, unit_vertex_normals(V, F), offset);
  std::vector<char> out(w.size());
  for (size_t i = 0; i < w.size(); ++i) out[i] = w[i] >= 1;
  return out;
}

BodyYield yield_self_overlap(const Faces& F, Points3& V, const Points3& rest, const std::vector<int>& segment,
                             const BodyYieldOptions& opt) {
  if (rest.rows() != V.rows()) fail("yield_self_overlap", "rest pose and frame differ in vertex count");
  if (!segment.empty() && static_cast<Eigen::Index>(segment.size()) != V.rows())
    fail("yield_self_overlap", "segment labels and frame differ in vertex count");
  // Whose face a ray from vertex i crosses: its own part's (a corner in its limb segment, or
  // with no labels, near it in the rest pose), another part's (every corner in another segment
  // and far in the rest pose), or, in between, a neighbouring part's across a joint's crease.
  enum class Whose { Own, Crease, Other };
  const double sep2 = opt.part_separation * opt.part_separation;
  auto close_at_rest = [&](Eigen::Index i, Eigen::Index j) {
    return (rest.row(i) - rest.row(j)).squaredNorm() <= sep2;
  };
  auto same_part = [&](Eigen::Index i, Eigen::Index j) {
    return segment.empty() ? close_at_rest(i, j) : segment[i] == segment[j];
  };
  auto whose = [&](Eigen::Index i, int f) {
    bool near = false;
    for (int c = 0; c < 3; ++c) {
      if (same_part(i, F(f, c))) return Whose::Own;
      near = near || close_at_rest(i, F(f, c));
    }
    return near ? Whose::Crease : Whose::Other;
  };
  BodyYield r;
  const Points3 V0 = V;
  std::vector<char> moved(V.rows(), 0);
  const double probe = (1 - kGapTolerance) * opt.gap;
  for (int pass = 0; pass < opt.max_passes; ++pass) {
    const BodyQuery q(TriMesh{V, F});
    const Points3 N = unit_vertex_normals(V, F);
    const std::vector<int> w = offset_winding(q, V, N, probe);
    std::vector<Eigen::Index> buried;
    for (Eigen::Index i = 0; i < V.rows(); ++i)
      if (w[i] >= 1) buried.push_back(i);
    // Inwards from the probe point, past the vertex's own part, to the first face of another
    // part: where that part ends (the ray leaves it there) if the vertex is buried in it.
    const auto nb = static_cast<Eigen::Index>(buried.size());
    Points3 O(nb, 3), D(nb, 3);
    for (Eigen::Index k = 0; k < nb; ++k) {
      D.row(k) = -N.row(buried[k]);
      O.row(k) = V.row(buried[k]) + probe * N.row(buried[k]);
    }
    const double reach = probe + opt.max_depth;
    const auto cross = crossings(q, O, D, reach);
    std::vector<Dent> dents;
    for (Eigen::Index k = 0; k < nb; ++k) {
      const Eigen::Index i = buried[k];
      const Crossing* out = nullptr;
      Whose first = Whose::Own;
      for (const Crossing& c : cross[k])
        if ((first = whose(i, c.face)) != Whose::Own) {
          out = &c;
          break;
        }
      // Left as skinned: a fold of the skin in a joint's crease (the ray meets the part across
      // the joint first, or enters another part), or deeper than max_depth.
      if (!out || first != Whose::Other || out->sign < 0) continue;
      // Half the way to the gap: the part it is buried in gives way by the other half.
      dents.push_back({i, 0.5 * (out->t - probe + opt.gap)});
    }
    r.buried_left = static_cast<int>(dents.size());
    if (dents.empty()) break;
    const Eigen::VectorXd depth = dent_depths(V, N, dents, same_part, opt.dent_falloff);
    for (Eigen::Index j = 0; j < V.rows(); ++j)
      if (depth(j) > 0) {
        V.row(j) -= depth(j) * N.row(j);
        moved[j] = 1;
      }
  }
  r.vertices_moved = static_cast<int>(std::count(moved.begin(), moved.end(), 1));
  r.max_move = V.rows() > 0 ? (V - V0).rowwise().norm().maxCoeff() : 0.0;
  return r;
}

}  // namespace gdsr

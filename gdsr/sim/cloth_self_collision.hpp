// Cloth self-collision for the XPBD solver: vertex-triangle and edge-edge proximity
// constraints that keep non-adjacent parts of the cloth at least `thickness` metres apart.
//
// Broad phase: Embree's rtcCollide (vertices against faces, edges against edges and against
// faces for the tangle test) on boxes swept along each vertex's predicted motion until the
// next detection, less the cloth's mean motion (a frame moving with the cloth: the same shift
// for every vertex changes no pair's relative motion), and grown by a slack, so every pair that can
// meet before the next detection is found (no tunnelling while each vertex stays within the
// slack of its predicted path; as soon as one leaves it, the solver gives it a new path and
// finds its pairs again, redetect, against the boxes the detection built for the rest). Narrow
// phase: exact point-triangle and segment-segment distances against the pair's relative
// motion, so cloth that moves along together does not pay for its speed. Only pairs whose two
// boxes overlap are kept (Embree's collide also reports some pairs of a BVH leaf whose own boxes
// do not, and which ones depended on the BVH), so the edges can be split into chunks whose pairs
// are jobs for the two threads; the narrow phase runs inside Embree's callbacks, so only the
// pairs it keeps are stored.
//
// Side memory: each pair stores on which side of the triangle (vertex-triangle: sign along
// the face normal) or of the other edge (edge-edge: the unit separation between the closest
// points) it was when found, and the constraint pushes it back to that side. The side is
// refreshed while crossing is legal (the vertex projects outside the triangle; the closest
// points of the edges lie at an end) and, for edges, while they are apart on that side.
// Optionally (set_refuse_crossing_pushes) a push back to the remembered side that would make the
// pair's faces intersect where they do not is refused, and the pair takes the side it is on.
//
// Untangling: edges that already cross a triangle (an intersection that slipped through)
// mark their and the triangle's vertices "tangled"; pairs with a tangled vertex on both sides
// (the vertex and the triangle, or both edges), or found deeper on the wrong side than their
// motion since the detection can explain, get no constraint, and their side follows the
// geometry, so an intersection is never locked in: stretch and bending pull the layers apart and
// the pair is guarded again once free. A pair tangled on one side only is still guarded: a
// third layer lying on two that crossed is kept on its side of them (freed too, before solver
// revision 31, it passed through them, and the knot spread through a stack of layers).
// untangle() also moves them apart actively: each edge still crossing a face is moved against
// it down the gradient of the intersection contour's length (Volino and Magnenat-Thalmann
// 2006, "Resolving surface collisions through intersection contour minimization"), so a
// closed contour shrinks to nothing and the part poking through goes back.
//
// Pairs sharing a vertex are skipped (the mesh's own stretch and bending act there).
//
// Deterministic: candidate pairs are collected in any order (Embree, OpenMP), sorted, then
// solved in that fixed order.
#pragma once

#include "gdsr/geometry/mesh.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

namespace sim {

class SelfCollision {
 public:
  // F: cloth triangles (indices into num_vertices welded vertices).
  SelfCollision(const gdsr::Faces& F, int num_vertices);
  ~SelfCollision();
  SelfCollision(const SelfCollision&) = delete;
  SelfCollision& operator=(const SelfCollision&) = delete;

  // Finds every non-adjacent vertex-triangle and edge-edge pair that can come within
  // `thickness` metres while each vertex v stays within `slack` metres of its path
  // x.row(v) + a motion.row(v), a in [0, 1]; their sides are taken from x (assumed
  // intersection-free except for tangled regions). The paths are boxed in a frame that moves
  // with the mean motion (only relative motion brings cloth together), so cloth carried
  // along fast costs no more than cloth at rest. tangle_test: also look for edges crossing
  // triangles and refresh the tangled vertices (otherwise the last ones are kept). The
  // broad phase's trees are built anew at a detection with the tangle test (the solver's first
  // of each frame) and refitted to the new boxes at the others (same tree, new boxes: the same
  // pairs, as each pair's own boxes are tested).
  void detect(const gdsr::Points3& x, const gdsr::Points3& motion, double slack, double thickness,
              bool tangle_test = true);

  // After detect, when some vertices left their slack: moved[v] != 0 marks the vertices whose
  // path changed since that detect, `elapsed` in [0, 1] the part of the detect's interval gone
  // by. Every vertex v is now on the path start.row(v) + a motion.row(v), a in [0, 1], until
  // the end of the detect's interval (for an unmoved vertex, the rest of the path it was
  // detected on). The pairs of every vertex, edge and face with a
  // moved vertex are found again by detect's rule on these paths, their sides taken from x (the
  // current positions, intersection-free); the other pairs are kept as they were. Only the moved
  // primitives' boxes are rebuilt, and collided with the scenes detect built (their boxes still
  // bound the unmoved primitives' paths), so this costs a fraction of a detect when few moved.
  // Tangled vertices are not refreshed.
  void redetect(const gdsr::Points3& x, const gdsr::Points3& start, const gdsr::Points3& motion,
                const std::vector<char>& moved, double elapsed, double slack, double thickness);

  // One Gauss-Seidel pass over the pairs (fixed order): pushes pairs closer than
  // `thickness` apart along the triangle normal / edge-edge normal, by inverse masses winv
  // (0 = fixed), by at most `max_crossed_push` metres: set it to `thickness` or more, and it
  // limits only pairs found crossed (on the other side from the one they were detected on,
  // within their reach). min_mass_share: a pair's generalised inverse mass is taken as at least
  // this fraction of its largest vertex's inverse mass, so that where the only free vertices carry
  // little of the contact point (the others pinned) the push does not move them by C over their
  // weight; pairs of free vertices of like masses are never below 0.25 (a vertex against a free
  // face: 1 + 1/3 and more; two free edges: 1 and more). Returns the number of pairs pushed.
  // From kTwoThreadProjectPairs pairs (and two OpenMP threads allowed) the pass runs on two
  // threads, with the one-thread result bit for bit (cloth_self_contact_projection.cpp).
  static constexpr size_t kTwoThreadProjectPairs = 4096;
  int project(gdsr::Points3& x, const std::vector<double>& winv, double thickness,
              double max_crossed_push = std::numeric_limits<double>::infinity(), double min_mass_share = 0);

  // One step of intersection contour minimisation over the edge-face crossings of the last
  // tangle test that still cross in x: the edge and the face are moved apart (by inverse
  // masses winv) along the direction that shortens the contour, no vertex by more than
  // `step` metres. Returns the number of crossings that were still crossing.
  int untangle(gdsr::Points3& x, const std::vector<double>& winv, double step);

  // Pairs the last project() pushed back from the other side of their remembered one.
  int num_crossed_pushed() const { return crossed_pushed_; }
  // refuse: a push back across (as above) that would make the pair's faces intersect where they
  // do not is refused, and the pair takes the side it is on: its remembered side was taken from
  // positions that body contacts had pressed through (SimParams::self_refuse_crossing_push has the
  // trade; off by default). num_sides_corrected: the pushes the last project() refused.
  void set_refuse_crossing_pushes(bool refuse) { refuse_crossing_pushes_ = refuse; }
  // body_moved (per vertex, 1: a body contact moved it in this iteration; kept by the caller,
  // null: every vertex counts as moved): only pushes of pairs with such a vertex are refused.
  // Where a limb holds a layer through another (at 10 mm farther than a face's width, so the
  // faces around the pair no longer intersect), the push back is then still made.
  void set_body_moved(const std::vector<char>* body_moved) { body_moved_ = body_moved; }
  int num_sides_corrected() const { return sides_corrected_; }
  int num_vertex_triangle() const { return static_cast<int>(vt_.size()); }
  int num_edge_edge() const { return static_cast<int>(ee_.size()); }
  // Vertices of edges and triangles found crossing each other at the last tangle test.
  int num_tangled_vertices() const;
  const std::vector<char>& tangled() const { return tangled_; }  // per vertex, 1: tangled (as above)
  // Edge-triangle pairs (no shared vertex) found crossing at the last tangle test.
  int num_intersecting_pairs() const { return intersecting_; }
  long long num_detections() const { return detections_; }      // since construction
  long long num_redetections() const { return redetections_; }  // since construction
  // The pairs kept: (vertex, face) and (edge a, edge b), edges numbered as in edges().
  std::vector<std::array<int, 2>> vertex_triangle_pairs() const;
  std::vector<std::array<int, 2>> edge_edge_pairs() const;
  const std::vector<std::array<int, 2>>& edges() const { return edges_; }  // unique edges (i < j)

 private:
  // reach: metres the pair may be found on the wrong side of its remembered side before it is
  // taken for an intersection that slipped through (and freed, see "Untangling"): thickness
  // plus the pair's relative motion over the detection interval plus both slacks, the most
  // its predicted motion can carry it. Pushing deeper pairs back tore the cloth: on CMU salsa
  // 60_03, cloth crushed between a hand and a pinned waistband was pushed 1-7 cm per pass
  // into a spike.
  struct VT {
    int v, f;
    signed char side;
    float reach;
  };
  struct EE {  // edge ids a < b; dir: unit separation (edge a minus edge b) on the remembered side
    int a, b;
    float dir[3];
    float reach;
    void set_dir(const gdsr::Vec3& u) {
      dir[0] = static_cast<float>(u.x()), dir[1] = static_cast<float>(u.y()), dir[2] = static_cast<float>(u.z());
    }
  };
  // Per detection: what the narrow phase tests the broad phase's pairs against.
  struct Narrow {
    const gdsr::Points3* x;
    const gdsr::Points3* motion;
    double slack, thickness;
    const gdsr::Points3* side = nullptr;  // positions the pairs' sides are taken from (null: x)
  };
  // Narrow phase of one pair: true (and `out` filled) if it is kept. Vertex v and face f
  // within reach (VT), edges a < b within reach (EE), edge e crossing face f (tangle test).
  bool narrow_phase(const Narrow& n, int v, int f, VT& out) const;
  bool narrow_phase(const Narrow& n, int a, int b, EE& out) const;
  bool narrow_phase(const Narrow& n, int e, int f, std::array<int, 2>& out) const;
  // The kept pairs in a fixed order (the broad phase's is not), repeats dropped.
  void sort_pairs();
  // The contact projection (cloth_self_contact_projection.cpp). project_pair: one pair's
  // constraint at positions x; true if it pushes, with what the push adds to its four vertices
  // in `out`; else at most the pair's remembered side changes.
  struct ProjectLimits {
    const std::vector<double>* winv;
    double thickness, max_crossed_push, min_mass_share;
  };
  struct PairPush {
    int v[4];
    gdsr::Vec3 d[4];
    bool crossed;  // the pair was on the other side from its remembered one
    void apply(gdsr::Points3& x) const {
      for (int k = 0; k < 4; ++k) x.row(v[k]) += d[k].transpose();
    }
  };
  bool project_pair(const gdsr::Points3& x, const ProjectLimits& l, VT& c, PairPush& out) const;
  bool project_pair(const gdsr::Points3& x, const ProjectLimits& l, EE& c, PairPush& out) const;
  template <class Pair> int project_in_order(gdsr::Points3& x, const ProjectLimits& l, std::vector<Pair>& pairs);
  // The second phase (see the .cpp): `evaluated` and `pushes` hold the first phase's pairs and
  // verdicts; `pairs` gets the pass's. moved_*: the vertices, faces and edges pushed so far this
  // pass. `redone` counts the pairs evaluated again.
  template <class Pair> int project_speculated(gdsr::Points3& x, const ProjectLimits& l, std::vector<Pair>& pairs,
                                               std::vector<Pair>& evaluated, const std::vector<char>& pushes,
                                               size_t& redone);
  // With set_refuse_crossing_pushes: a push back across that makes the pair's faces (VT: the
  // vertex's faces and the triangle; EE: the two edges' faces) intersect where they did not is
  // refused and the pair takes the current side. True if refused.
  bool refuse_crossing_push(gdsr::Points3& x, VT& c, const PairPush& push);
  bool refuse_crossing_push(gdsr::Points3& x, EE& c, const PairPush& push);
  bool faces_cross(const gdsr::Points3& x, const int* fa, int na, const int* fb, int nb) const;
  bool faces_cross(const gdsr::Points3& x, const VT& c) const;
  bool faces_cross(const gdsr::Points3& x, const EE& c) const;
  // True if `push` would make the pair's faces intersect where they do not now; x is left as it was.
  template <class Pair> bool push_makes_crossing(gdsr::Points3& x, const Pair& c, const PairPush& push) const;
  // A tangled vertex on both sides of the pair: part of an intersection that slipped through (see
  // "Untangling"), left free.
  bool tangled_on_both_sides(const VT& c) const {
    return tangled_[c.v] && (tangled_[F_(c.f, 0)] || tangled_[F_(c.f, 1)] || tangled_[F_(c.f, 2)]);
  }
  bool tangled_on_both_sides(const EE& c) const {
    return (tangled_[edges_[c.a][0]] || tangled_[edges_[c.a][1]]) &&
           (tangled_[edges_[c.b][0]] || tangled_[edges_[c.b][1]]);
  }
  bool touches(const VT& c) const { return moved_v_[c.v] | moved_f_[c.f]; }
  bool touches(const EE& c) const { return moved_e_[c.a] | moved_e_[c.b]; }
  void mark_moved(const PairPush& push);
  bool body_touched(const PairPush& push) const;
  gdsr::Faces F_;
  std::vector<std::array<int, 2>> edges_;  // unique edges (i < j)
  std::vector<std::array<int, 2>> edge_faces_;  // the (one or two) faces of each edge, -1: none
  std::vector<std::array<int, 2>> crossings_;   // (edge, face) crossing at the last tangle test, sorted
  std::vector<gdsr::Vec3> untangle_move_;       // per vertex, scratch of untangle()
  std::vector<VT> vt_;
  std::vector<EE> ee_;
  std::vector<char> tangled_;
  std::vector<VT> speculated_vt_;  // project's first phase, kept to reuse the memory
  std::vector<EE> speculated_ee_;
  std::vector<char> pushes_vt_, pushes_ee_, moved_v_, moved_f_, moved_e_;
  gdsr::Csr vertex_faces_, vertex_edges_;  // around each vertex, for moved_f_ and moved_e_
  double last_redone_share_ = 0;           // of the pairs, by the last two-phase pass
  int passes_in_order_ = 0;                // since then
  int intersecting_ = 0;
  int crossed_pushed_ = 0;
  int sides_corrected_ = 0;
  bool refuse_crossing_pushes_ = false;
  const std::vector<char>* body_moved_ = nullptr;  // see set_body_moved
  long long detections_ = 0;
  long long redetections_ = 0;
  struct Embree;
  std::unique_ptr<Embree> embree_;
};

}  // namespace sim

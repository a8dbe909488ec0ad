// Flesh that gives way: where linear-blend skinning drives one part of a body into another (a
// thigh raised into the belly in a kneel, a forearm folded onto the upper arm), the skinned
// surface passes through itself, and cloth caught between the two parts is pushed out of each
// into the other. yield_self_overlap moves the buried surface back instead, each side half the
// overlap, so that the two parts meet at a common surface `gap` apart, as flesh pressed
// together would.
//
// "Buried": a vertex whose point `gap` outside it, along its normal, lies inside the body
// (winding number >= 1, counted along rays with Embree). Its depth is measured along its
// inward normal, past its own part, to the first face of another part, where the ray must
// leave that part; it moves half of that plus half the gap (the other side moves its half in
// the same pass), and takes its part's surface around it along, less with distance, so the
// flesh dents rather than one vertex sinking into a pit (dent_falloff). Passes repeat on the
// moved surface until nothing is buried (a side with no vertex inside the other, a limb's
// tip, leaves the rest to the next pass).
// Another part: every corner of the face lies in another limb segment (per-vertex labels, a
// thigh, a forearm, the trunk) and was farther than part_separation from the vertex in the
// rest pose (the validity figures' "body crosses itself" counts faces 0.15 m apart; 0.10 also
// takes the belly and the inner thigh, 10-17 cm apart at the hip crease); the ray passes the vertex's own
// segment's faces. A buried vertex whose ray meets a neighbouring segment's face near it in
// the rest pose first (across a joint), enters another part, or meets none within max_depth, is a fold of the
// skin in a joint's crease (an armpit), not flesh pressed on flesh, and stays as skinned.
// Positions in metres. Deterministic; surfaces that do not pass through themselves are
// returned bit for bit.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <vector>

namespace gdsr {

struct BodyYieldOptions {
  double gap = 0.004;             // m: the two sides end at least about this far apart at the vertices
  double max_depth = 0.10;        // m: a vertex whose ray finds no other part within this stays as skinned
  int max_passes = 12;            // passes over the moved surface
  double part_separation = 0.10;  // m, in the rest pose: farther apart are two parts (a thigh and the belly)
  double dent_falloff = 0.02;     // m: a buried vertex moving d takes its part's surface within this + d along
};

struct BodyYield {
  int vertices_moved = 0;  // vertices moved in any pass
  double max_move = 0;     // m: the largest total move of a vertex
  int buried_left = 0;     // vertices still inside another part in the last pass (0: all given way)
};

// V: vertices x 3 of a closed, outward-oriented surface F (a body frame), moved in place; rest:
// the same surface in its rest pose; segment: per vertex, its limb segment (any ids; empty: the
// rest-pose distance alone tells the parts apart). Throws on mismatched counts.
BodyYield yield_self_overlap(const Faces& F, Points3& V, const Points3& rest, const std::vector<int>& segment,
                             const BodyYieldOptions& opt = {});

// Per vertex: 1 where the point `offset` metres outside it along its area-weighted normal lies
// inside the surface (winding number >= 1 along two rays), else 0.
std::vector<char> buried_vertices(const Faces& F, const Points3& V, double offset);

}  // namespace gdsr

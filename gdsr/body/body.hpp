// Animated bodies: a closed, outward-oriented triangle surface per frame, loaded with
// assimp from any file with skeletal animation (BVH, FBX, glTF/GLB, Collada).
//
// - Skinned mesh in the file (not BVH): linear-blend skinning of that mesh (vertices welded
//   by position). Closedness is whatever the file's mesh is.
// - Bare skeleton (BVH, or no skinned mesh): a smooth body is built around the bones once
//   at the rest pose (smooth union of tapered/elliptic capsules and ellipsoids, meshed by
//   marching tetrahedra + CGAL isotropic remeshing: closed, manifold, outward normals,
//   deterministic) and skinned to the bones (<= 4 per vertex, by distance to the parts).
//   Upper arms hanging more than 60 degrees below the horizontal in the file's rest pose are
//   first raised level at the shoulder (a T-pose); the motion itself is not changed.
//
// Output coordinates: metres, y up. Every body is scaled uniformly so that its rest pose is
// opt.height tall (y extent; for skeleton bodies counting the legs as vertical, so a rest
// pose with spread legs is a bit lower than opt.height), and translated so that the rest pose stands on y = 0 with
// its bounding-box centre at x = z = 0; the same similarity transform is applied to all
// frames, so root motion is kept. The file's UpAxis metadata (FBX) is honoured.
//
// Frames: the first rest_blend_frames frames go from the rest pose (frame 0 is exactly the
// rest pose) to the first motion frame: per joint, rotations slerp and scales lerp with a
// smoothstep weight. The rest pose keeps each animated node's translation from the first
// motion frame (so the body does not jump), with the rotations/scales of the file's rest
// (offset/bind) pose. Then one frame per 1/fps seconds of the clip from start_seconds,
// bone keys interpolated (positions lerp, rotations slerp). Clip times (start_seconds,
// max_seconds) count from the first motion key (see skip_calibration_key).
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <string>
#include <vector>

namespace gdsr {

struct BodyOptions {
  double fps = 30.0;           // output frame rate (frames per second)
  double height = 1.75;        // bodies are scaled to this standing height (rest pose), metres
  int rest_blend_frames = 15;  // frames blending from the rest pose into the first motion frame
  double start_seconds = 0.0;  // where in the clip to start
  double max_seconds = -1.0;   // clip length to use (<0: all)
  // Skeleton bodies only: target edge length of the body mesh, metres (smaller = more
  // triangles; 0.028 gives about 6k triangles for a 1.75 m body).
  double body_edge = 0.028;
  // Mocap clips (e.g. CMU BVH) often start with one calibration T-pose key that jumps to
  // the motion: when the first key differs from the second by a much larger rotation than
  // the second from the third, the clip is taken to start at the second key.
  bool skip_calibration_key = true;
  // The rest pose (frame 0, where garments are put on) with each upper arm turned about its
  // shoulder to point sideways this many degrees below the horizontal (45: an A-pose; the
  // t-shirt's sleeves are cut for it). < 0: the file's rest pose. The body mesh, its scale
  // and its placement come from the file's rest pose either way: only frame 0 and the rest
  // blend from it change; every motion frame after the blend is the same.
  double rest_arm_drop_degrees = -1;
  // Motion capture of a slim actor on a rounder body lets an arm pass through the trunk or the
  // legs (a forearm swinging past the hip). > 0: in every frame after the first, an upper arm
  // that comes closer than this many metres to the rest of the body is turned about its
  // shoulder, away from the body, by the smallest angle that clears it (at most
  // max_arm_turn_degrees), eased in and out over arm_turn_ease_seconds. 0: the motion as in
  // the file. Bodies without two recognisable upper arms are left as they are.
  double arm_clearance = 0;
  double max_arm_turn_degrees = 30;
  double arm_turn_ease_seconds = 0.2;
  // Skeleton bodies only: shoulder joints closer than this many metres to the middle (at the
  // rest pose, on a body `height` tall) are moved out, level, to it, in their parent's frame, so
  // the collar carries them through the motion. The trunk is built to an anatomical width, and
  // narrower shoulders hang the arms inside it (the CMU salsa BVHs: 0.126 m; CMU 01: 0.213 m,
  // CMU 131: 0.204 m). 0: the joints where the file has them.
  double min_shoulder_half_width = 0.20;
  // > 0: where skinning drives one part of the body into another (a thigh raised into the belly,
  // a forearm folded onto the upper arm), both surfaces give way, each half the overlap, to meet
  // this many metres apart, as flesh does (gdsr/body/body_yield.hpp). 0: the skinned surface as it is.
  double yield_gap = 0;
};

// Of a per-frame amount of change (0: the frame as it was): the frames changed, the largest.
inline int frames_changed(const std::vector<double>& per_frame) {
  int n = 0;
  for (double d : per_frame) n += d > 0;
  return n;
}
inline double largest_change(const std::vector<double>& per_frame) {
  double m = 0;
  for (double d : per_frame) m = d > m ? d : m;
  return m;
}

// How BodyOptions::yield_gap changed the frames.
struct BodyYields {
  std::vector<double> max_move;  // per frame, m: the largest move of a vertex (0: as skinned)
  int buried_left_frames = 0;    // frames with vertices still inside another part after the last pass
  int yielded_frames() const { return frames_changed(max_move); }
  double max_move_overall() const { return largest_change(max_move); }
};

// How BodyOptions::arm_clearance changed the motion.
struct ArmTurns {
  std::vector<double> degrees;  // per frame, the larger of the two arms' turns (0: as in the file)
  int still_inside_frames = 0;  // turned frames where an arm still enters the body (the turn capped)
  int turned_frames() const { return frames_changed(degrees); }
  double max_degrees() const { return largest_change(degrees); }
};

// A horizontal cross-section of the rest-pose body (torso only: points within 0.35 m of
// the torso axis), metres.
struct BodySection {
  double y = 0;              // height above the floor
  double cx = 0, cz = 0;     // centre of the section's bounding box
  double half_width = 0;     // half extent along x (left-right)
  double half_depth = 0;     // half extent along z (front-back)
  double circumference = 0;  // perimeter of the section's convex hull
};

// Landmarks of the rest pose for placing garments, metres, y up (same frame as frames[]).
// For skeleton bodies waist/hip heights come from the torso construction; for skinned meshes
// they are fixed fractions of the height (waist 0.61 H, hips 0.52 H).
struct BodyLandmarks {
  double height = 0;      // standing height (== opt.height), see above
  BodySection waist;      // narrowest part of the torso (skirt waistband)
  BodySection hips;       // widest part of the pelvis
  BodySection chest;      // chest/bust level (tops)
  double crotch_y = 0;    // lowest body point straight above the hip centre
  double shoulder_y = 0;  // height of the shoulder joints (skeleton) or 0.82 H
};

struct BodySequence {
  Faces F;                      // one topology for all frames, closed surface, outward normals
  std::vector<Points3> frames;  // per output frame: vertices x 3, metres, y up
  double fps = 30.0;
  int rest_blend_frames = 0;   // the first frames are the blend from rest pose
  std::string source;          // file it came from
  Points3 rest_V;              // rest pose vertices x 3 (== frames[0] when rest_blend_frames > 0)
  BodyLandmarks landmarks;     // measured on the rest pose
  bool from_skeleton = false;  // true: body built around a bare skeleton
  // Skeleton bodies: hips and shoulders recognised by joint name (false: a shoulderless column
  // of capsules; `gdsr data make` warns). Always true for skinned meshes.
  bool torso_found = true;
  ArmTurns arm_turns;  // empty degrees unless BodyOptions::arm_clearance > 0
  BodyYields yields;   // empty max_move unless BodyOptions::yield_gap > 0
  // Skeleton bodies with two upper arms: the shoulder joints' distance from the middle as in
  // the file, metres (0: not measured), and whether BodyOptions::min_shoulder_half_width moved them.
  double captured_shoulder_half_width = 0;
  bool shoulders_widened = false;

  int num_frames() const { return static_cast<int>(frames.size()); }
  TriMesh frame_mesh(int t) const;  // throws on t out of range
  TriMesh rest_mesh() const { return TriMesh{rest_V, F}; }
};

// Loads and evaluates the whole clip. Throws gdsr::Error (one line naming the file)
// for a missing/unreadable file, a file without animation, without bones/skeleton, or bad
// options.
BodySequence load_body_sequence(const std::string& path, const BodyOptions& opt = {});

// Rest pose only (no frames evaluated besides the rest pose): mesh + landmarks.
// Equivalent to load_body_sequence(path, opt with max_seconds tiny).rest_mesh().
TriMesh load_body_rest(const std::string& path, const BodyOptions& opt = {}, BodyLandmarks* landmarks = nullptr);

// Measures a horizontal section of a closed mesh at height y (torso points within
// max_radius of (axis_x, axis_z)). Throws if the plane misses the mesh there.
BodySection measure_section(const TriMesh& mesh, double y, double axis_x, double axis_z, double max_radius = 0.35);

}  // namespace gdsr

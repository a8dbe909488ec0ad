// Validity figures of a paired LR/HR dataset (issue 10), each measured with a yardstick that is
// independent of the simulator that made the data, so they apply to any dataset (ours or a
// Marvelous Designer import):
//   - self-intersection: intersecting pairs of triangles per frame, CGAL
//     (gdsr/geometry/self_intersections.hpp; pairs meeting only at a shared vertex/edge do not
//     count), on every `intersection_stride`-th frame;
//   - strain: mean E_u, E_v, E_uv against the sewing pattern (gdsr/geometry/strain.hpp), and
//     torn cloth: the longest edge over its pattern length and the frames with an edge
//     longer than tear_stretch times it (a few dragged-out vertices that the means hide);
//   - body: penetration depth = -signed distance to the body frame (Embree, exact closest
//     point, gdsr/body/body_query.hpp), only when the dataset has a body; a penetrating
//     vertex is "pinched" when the surface of a second body part is within pinch_reach of it
//     (a body triangle whose corners were all farther than pinch_separation, in the first
//     frame, from the closest point; Embree point query, exact distance): cloth between a hand
//     and a hip cannot be outside both, so pinched frames are counted apart (the distance is
//     to the surface, not to the part's vertices, which are 25 mm apart on average on the
//     skinned bodies: there, a part whose surface was within reach could be missed); a
//     penetrating vertex is also pinched in a closed crease of one part (the crook of a bent
//     elbow, forearm and upper arm less than pinch_separation apart at rest): the ray from its
//     closest body point, on along the way out (vertex to closest point), meets the body again
//     within pinch_gap (Embree ray), less room than the cloth needs on both sides;
//     and the body's own crossings: frames where two body faces intersect (CGAL) whose
//     vertices were all farther than pinch_separation apart in the first frame (two parts:
//     a mocap forearm passing into the trunk; the skin creasing at a bent joint does not
//     count), and the pinch frames among them (the motion leaves the cloth no room); and cloth
//     threaded on the body: frames with an edge whose two ends are outside the body while the
//     segment between them runs through it (Embree rays from both ends; the middle of its span
//     between the first and the last crossing deeper than threaded_depth): a hand or forearm
//     that passed between two cloth vertices and carries the cloth over itself;
//   - agreement: distance of each HR vertex to the LR frame upsampled to HR topology through
//     the dataset's correspondence (gdsr/geometry/correspondence.hpp), and split by scale with
//     HR's own shape at the LR scale, S = upsample(downsample(HR)): |S - upsample(LR)| is a
//     difference in drape, |HR - S| what the LR mesh cannot hold (wrinkles); the first is what
//     a perfect correction E of GDSR can remove, the second what is left for the detail A;
//   - wrinkles: mean absolute mean curvature of HR, LR upsampled and LR
//     (gdsr/geometry/wrinkles.hpp).
// Every figure is over all frames of the clip (rest-blend frames included). Units: metres,
// 1/m; strain energies are dimensionless.
#pragma once

#include "gdsr/data/dataset.hpp"
#include "gdsr/geometry/strain.hpp"
#include "gdsr/io/progress.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace gdsr {

struct ValidityOptions {
  int intersection_stride = 1;       // self-intersections on frames 0, k, 2k, ... (>= 1)
  double penetration_limit = 0.005;  // metres: frames with a deeper vertex are counted
  bool body = true;                  // false: skip the penetration even if the dataset has a body
  double pinch_reach = 0.04;         // metres: a second body part this close to a penetrating vertex pinches it
  double pinch_separation = 0.15;    // metres apart in the first frame: two points on different body parts
  double pinch_gap = 0.008;          // metres: a crease of one part closed to less than this pinches the cloth in it
                                     // (two cloth thicknesses of 4 mm, as the solver keeps off the body); 0: off
  double tear_stretch = 2;           // frames with an edge longer than this times its pattern length are counted
  double threaded_depth = 0.005;     // metres: an edge with both ends outside the body and its middle inside deeper
                                     // than this is threaded (a chord of cloth resting on a wrist dips ~2 mm)
};

// Figures of one resolution (LR or HR) over the clip.
struct ResolutionValidity {
  int faces = 0;
  // self-intersection (frames checked: every stride-th)
  int si_frames = 0;           // frames checked
  int si_clean_frames = 0;     // checked frames with zero intersecting pairs
  double si_median_pairs = 0;  // median over the checked frames
  long si_max_pairs = 0;
  int si_max_frame = -1;         // frame of si_max_pairs
  long si_degenerate_faces = 0;  // max over checked frames of degenerate (collinear) faces
  long si_skipped_faces = 0;     // non-manifold faces left out of the test (same every frame)
  double si_clean_fraction() const { return si_frames > 0 ? static_cast<double>(si_clean_frames) / si_frames : 0; }
  // Knots: runs of consecutive checked frames with intersecting pairs (cloth that stays through
  // itself for 30 frames is one knot), and those whose first frame has the body crossing itself
  // (body_crossing_frames), with their checked frames: where the body leaves the cloth no room,
  // apart from where the solver let it through. -1: not measured (no body, or an older manifest).
  int si_knots = 0;
  int si_knots_from_body_crossings = -1;
  int si_knot_frames_from_body_crossings = -1;
  // The longest knot (the most checked frames; the first of equals): its first and last checked
  // frames (-1: no knot, or an older manifest), and the two cloth layers (0 = innermost) that the
  // most intersecting pairs of its first frame join, where it began: the same layer twice for a
  // fold through itself; -1 for a garment of one layer.
  int si_longest_knot_first = -1, si_longest_knot_last = -1;
  std::array<int, 2> si_longest_knot_layers = {-1, -1};
  // strain, means over frames of the per-frame means over triangles
  StrainEnergies strain;
  double max_edge_stretch = 0;      // longest edge / pattern length, max over frames
  int max_edge_stretch_frame = -1;  // its frame
  int torn_frames = 0;              // frames with an edge longer than tear_stretch (-1: not measured)
  int torn_vertices = 0;            // distinct cloth vertices at the ends of such edges over the clip (-1: not
                                    // measured): a few when one spot is overstretched frame after frame
  // body (only when measured)
  double max_penetration = 0;      // metres, max over frames and vertices of -signed distance (0: none)
  int max_penetration_frame = -1;  // -1: no vertex penetrates in any frame
  int frames_over_limit = 0;       // frames whose max penetration exceeds the limit
  // the same over vertices that are not pinched (see the header comment)
  double max_penetration_free = 0;
  int max_penetration_free_frame = -1;
  int frames_over_limit_free = 0;
  int pinch_frames = 0;  // frames where a pinched vertex is deeper than the limit
  int pinch_frames_in_body_crossings = 0;  // of those, frames where the body crosses itself (-1: not measured)
  int threaded_frames = 0;                 // frames with cloth threaded on the body (see above; -1: not measured)
  long max_threaded_edges = 0;             // the most threaded edges in a frame
  int max_threaded_frame = -1;             // its frame (-1: none in any frame)
  double mean_curvature = 0;       // 1/m, mean over frames
};

// One frame's figures (ValidityFigures::per_frame; not stored in the manifest).
struct FrameValidity {
  long lr_pairs = -1, hr_pairs = -1;  // intersecting triangle pairs (-1: frame not checked, see the stride)
  // The two cloth layers that most of those pairs join, inner first ({-1, -1}: no pairs, or one layer).
  std::array<int, 2> lr_layers = {-1, -1}, hr_layers = {-1, -1};
  double lr_depth = 0, hr_depth = 0;  // metres, deepest vertex under the body surface outside pinches (0: none)
  double agreement = 0;               // metres, mean |HR - upsampled LR|
  long lr_threaded = 0, hr_threaded = 0;  // edges of cloth threaded on the body (0 without a body)
  bool body_crossing = false;             // two body parts intersect (see body_crossing_frames)
};

struct ValidityFigures {
  int frames = 0;
  int intersection_stride = 1;
  double penetration_limit = 0.005;  // metres
  double tear_stretch = 2;           // see ValidityOptions
  double threaded_depth = 0.005;     // metres, see ValidityOptions
  double pinch_gap = 0.008;          // metres, see ValidityOptions (0 in manifests measured before the crease rule)
  bool body_measured = false;
  int body_crossing_frames = 0;  // frames where two body parts intersect (see above; -1: not measured)
  ResolutionValidity lr, hr;
  // agreement: per frame, the mean over HR vertices of |HR - upsample(LR)|, metres
  double agreement_mean = 0;  // averaged over the clip
  double agreement_max = 0;   // the worst frame's mean
  int agreement_max_frame = -1;
  double agreement_rest = 0;            // the same on the canonical (rest) meshes
  // The split by scale (header comment), means over the clip (NaN: figures written before it):
  double agreement_lr_scale = 0;        // mean |upsample(downsample(HR)) - upsample(LR)|, metres
  double agreement_finer = 0;           // mean |HR - upsample(downsample(HR))|, metres
  double upsampled_mean_curvature = 0;  // 1/m, LR upsampled to HR topology, mean over frames
  std::vector<FrameValidity> per_frame;  // the figures of each frame (not in the manifest)
  // HR / LR of a strain figure (NaN when LR's is below 1e-12)
  double strain_ratio_u() const;
  double strain_ratio_v() const;
  double strain_ratio_uv() const;
  // HR / LR of the stretched-fibre part of E_u / E_v (NaN as above, or when not measured)
  double stretched_ratio_u() const;
  double stretched_ratio_v() const;
};

// Computes every figure from the dataset (frames must be loaded). Throws gdsr::Error on a
// dataset without frames or a stride < 1. progress(done, total) counts frames.
ValidityFigures measure_validity(const Dataset& d, const ValidityOptions& opt = {}, const ProgressFn& progress = {});

// Each garment vertex's depth under the body surface in frame t, by the rule of the body
// figures above: X is that frame's LR or HR positions (N x 3, metres). Throws gdsr::Error when
// the dataset has no body or t is out of range.
struct BodyDepths {
  std::vector<double> depth;  // N, metres, 0 where the vertex is outside the body
  std::vector<char> pinched;  // N, 1 where a second body part is within pinch_reach or a closed crease holds it
                              // (only where depth > 0; see the header comment)
};
BodyDepths body_depths(const Dataset& d, int t, const Points3& X, const ValidityOptions& opt = {});

// Whether two faces of a body mesh (V: one frame, N x 3, metres) intersect (CGAL) whose corners
// were all farther than sep metres apart in `rest` (its first frame): one part inside another,
// as counted by ValidityFigures::body_crossing_frames with sep = pinch_separation.
bool body_crosses_itself(const Points3& V, const Faces& F, const Points3& rest, double sep);
// ... and those pairs of faces (f, g), f < g, sorted.
std::vector<std::pair<int, int>> body_crossing_pairs(const Points3& V, const Faces& F, const Points3& rest, double sep);

// The per-frame figures as CSV text: a header, then one line per frame (frame, LR and HR
// intersecting pairs with -1 for unchecked frames, LR and HR depth outside pinches in mm,
// agreement in mm, LR and HR threaded edges).
std::string validity_per_frame_csv(const ValidityFigures& v);

// The manifest's "validity" object (docs/dataset-format.md) and back; from_json throws
// gdsr::Error naming the missing key.
nlohmann::json validity_to_json(const ValidityFigures& v);
ValidityFigures validity_from_json(const nlohmann::json& j);

// A small text table of the figures (several lines, each ending in '\n'), for the command line.
std::string validity_table(const ValidityFigures& v);

}  // namespace gdsr

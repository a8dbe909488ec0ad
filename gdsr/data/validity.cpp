#include "gdsr/data/validity.hpp"

#include "gdsr/error.hpp"

#include "gdsr/body/body_query.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/geometry/self_intersections.hpp"
#include "gdsr/geometry/wrinkles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace gdsr {
namespace {

// HR / LR, NaN when LR's figure is below 1e-12 (nothing to compare with; rounding noise).
double ratio(double hr, double lr) { return lr > 1e-12 ? hr / lr : std::numeric_limits<double>::quiet_NaN(); }

double median(std::vector<long> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? static_cast<double>(v[n / 2]) : 0.5 * static_cast<double>(v[n / 2 - 1] + v[n / 2]);
}

// The two layers that the most of `pairs` (faces of F) join, inner first; ties go to the lower
// pair. {-1, -1} without pairs or without layers (layer: per vertex, may be empty).
std::array<int, 2> commonest_layer_pair(const std::vector<std::pair<int, int>>& pairs, const Faces& F,
                                        const std::vector<int>& layer) {
  std::map<std::array<int, 2>, long> count;
  for (const auto& [f, g] : pairs) {
    const int a = layer[F(f, 0)], b = layer[F(g, 0)];
    ++count[{std::min(a, b), std::max(a, b)}];
  }
  std::array<int, 2> best = {-1, -1};
  long most = 0;
  for (const auto& [key, n] : count)  // in order: the first of equal counts is kept
    if (n > most) most = n, best = key;
  return best;
}

// Self-intersection figures of one resolution over the checked frames (frames in parallel:
// each CGAL call is independent).
// Each checked frame's pair count also goes to rows[t].*pairs, and for a garment of several
// layers (layer: per vertex) the layers most of its pairs join to rows[t].*layers.
void measure_intersections(const std::vector<Points3>& frames, const Faces& F, const std::vector<int>& layer,
                           int stride, ResolutionValidity& r, std::vector<FrameValidity>& rows,
                           long FrameValidity::*pairs_field, std::array<int, 2> FrameValidity::*layers_field) {
  const bool layered = !layer.empty() && *std::max_element(layer.begin(), layer.end()) > 0;
  const int T = static_cast<int>(frames.size());
  std::vector<int> checked;
  for (int t = 0; t < T; t += stride) checked.push_back(t);
  std::vector<SelfIntersections> si(checked.size());
  std::string error;
#pragma omp parallel for schedule(dynamic, 1)
  for (int k = 0; k < static_cast<int>(checked.size()); ++k) {
    try {
      si[k] = self_intersections(frames[checked[k]], F, /*list_pairs=*/layered);
    } catch (const std::exception& e) {
#pragma omp critical(validity_error)
      error = e.what();
    }
  }
  if (!error.empty()) throw Error(error);
  std::vector<long> pairs;
  r.si_frames = static_cast<int>(checked.size());
  for (size_t k = 0; k < checked.size(); ++k) {
    pairs.push_back(si[k].pairs);
    rows[checked[k]].*pairs_field = si[k].pairs;
    if (layered) rows[checked[k]].*layers_field = commonest_layer_pair(si[k].list, F, layer);
    r.si_clean_frames += si[k].pairs == 0;
    if (si[k].pairs > r.si_max_pairs || r.si_max_frame < 0) {
      r.si_max_pairs = si[k].pairs;
      r.si_max_frame = checked[k];
    }
    r.si_degenerate_faces = std::max(r.si_degenerate_faces, si[k].degenerate_faces);
    r.si_skipped_faces = std::max(r.si_skipped_faces, si[k].skipped_faces);
  }
  r.si_median_pairs = median(pairs);
}

// Knots of one resolution (ResolutionValidity::si_knots) from the checked frames' pair counts in
// rows (-1: not checked); the body's share when `body` (rows[t].body_crossing measured).
// The longest knot, its first and last frames and where it began (rows[first].*layers), too.
void count_knots(const std::vector<FrameValidity>& rows, long FrameValidity::*pairs_field,
                 std::array<int, 2> FrameValidity::*layers_field, bool body, ResolutionValidity& r) {
  r.si_knots = 0;
  r.si_knots_from_body_crossings = body ? 0 : -1;
  r.si_knot_frames_from_body_crossings = body ? 0 : -1;
  r.si_longest_knot_first = r.si_longest_knot_last = -1;
  r.si_longest_knot_layers = {-1, -1};
  bool in_knot = false, from_body = false;
  int first = -1, length = 0, longest = 0;
  for (size_t t = 0; t < rows.size(); ++t) {
    const FrameValidity& f = rows[t];
    const long pairs = f.*pairs_field;
    if (pairs < 0) continue;  // not checked (stride): runs join over it
    if (pairs == 0) {
      in_knot = false;
      continue;
    }
    if (!in_knot) {
      in_knot = true;
      ++r.si_knots;
      from_body = body && f.body_crossing;
      r.si_knots_from_body_crossings += from_body;
      first = static_cast<int>(t);
      length = 0;
    }
    r.si_knot_frames_from_body_crossings += from_body;
    if (++length > longest) {
      longest = length;
      r.si_longest_knot_first = first;
      r.si_longest_knot_last = static_cast<int>(t);
      r.si_longest_knot_layers = rows[first].*layers_field;
    }
  }
}

// Whether the way out of the body for garment vertex i (inside it), from its closest body point
// on along the direction from the vertex to that point, meets the body again within `gap`
// metres: the cloth lies in a crease closed to less than that (a bent elbow's crook).
bool in_closed_crease(const BodyQuery& body, const ClosestPoints& cp, const Points3& X, long i, double gap) {
  constexpr double kStart = 1e-4;  // metres past the closest point: the ray must not hit its own face
  if (!(gap > kStart)) return false;
  const Vec3 out = cp.point.row(i) - X.row(i);
  if (!(out.norm() > 1e-12)) return false;
  Points3 origin(1, 3), dir(1, 3);
  dir.row(0) = out.normalized().transpose();
  origin.row(0) = cp.point.row(i) + kStart * dir.row(0);
  return body.intersect(origin, dir, 0.0, gap - kStart).face(0) >= 0;
}

// Garment vertex i's depth under the body surface (metres, 0 when outside) and whether it is
// pinched: the surface of a second body part within reach of it, or a closed crease of its own
// part with less than pinch_gap of room (validity.hpp). cp: the body's closest points to the
// garment vertices X; body_rest: the body in the first frame, where body parts are told apart.
struct VertexDepth {
  double depth = 0;
  bool pinched = false;
};
VertexDepth vertex_depth(const BodyQuery& body, const ClosestPoints& cp, const Points3& body_rest, const Points3& X,
                         long i, const ValidityOptions& opt) {
  if (cp.face(i) < 0 || !(cp.sdist(i) < 0)) return {};
  const Faces& F = body.mesh().F;
  const double sep2 = opt.pinch_separation * opt.pinch_separation;
  const int f = cp.face(i);
  const Vec3 rest = cp.bary(i, 0) * body_rest.row(F(f, 0)) + cp.bary(i, 1) * body_rest.row(F(f, 1)) +
                    cp.bary(i, 2) * body_rest.row(F(f, 2));
  auto other_part = [&](int g) {  // every corner of g was farther than pinch_separation at rest
    for (int k = 0; k < 3; ++k)
      if ((body_rest.row(F(g, k)) - rest.transpose()).squaredNorm() <= sep2) return false;
    return true;
  };
  if (body.any_face_within(X.row(i).transpose(), opt.pinch_reach, other_part)) return {-cp.sdist(i), true};
  return {-cp.sdist(i), in_closed_crease(body, cp, X, i, opt.pinch_gap)};
}

struct Depths {
  double all = 0, free = 0, pinched = 0;  // deepest vertex under the body surface, metres (0 if none)
};

// Deepest garment vertex under the body surface, overall and split by pinch.
Depths penetration(const BodyQuery& body, const ClosestPoints& cp, const Points3& body_rest, const Points3& X,
                   const ValidityOptions& opt) {
  Depths d;
  for (long i = 0; i < X.rows(); ++i) {
    const VertexDepth v = vertex_depth(body, cp, body_rest, X, i, opt);
    if (!(v.depth > 0)) continue;
    d.all = std::max(d.all, v.depth);
    double& deepest = v.pinched ? d.pinched : d.free;
    deepest = std::max(deepest, v.depth);
  }
  return d;
}

// Edges of X (rows of `edges`) with both ends outside the body whose segment runs through it:
// the middle of its span between the first and the last crossing lies deeper than `depth`
// metres (validity.hpp; a chord grazing a curved surface dips in by a fraction of that).
// cp: the body's closest points to X (their signed distances tell the ends outside).
long threaded_edges(const BodyQuery& body, const ClosestPoints& cp, const Points3& X, const Pairs& edges,
                    double depth) {
  std::vector<int> out;  // edges with both ends outside
  for (int e = 0; e < edges.rows(); ++e) {
    const int i = edges(e, 0), j = edges(e, 1);
    if (cp.sdist(i) > 0 && cp.sdist(j) > 0 && (X.row(j) - X.row(i)).squaredNorm() > 1e-24) out.push_back(e);
  }
  const int n = static_cast<int>(out.size());
  if (n == 0) return 0;
  Points3 from(n, 3), to(n, 3);
  for (int k = 0; k < n; ++k) {
    from.row(k) = X.row(edges(out[k], 0));
    to.row(k) = X.row(edges(out[k], 1));
  }
  const Points3 dir = to - from;
  const RayHits enter = body.intersect(from, dir, 0.0, 1.0), leave = body.intersect(to, -dir, 0.0, 1.0);
  std::vector<int> crossing;
  for (int k = 0; k < n; ++k)
    if (enter.face(k) >= 0 && leave.face(k) >= 0) crossing.push_back(k);
  if (crossing.empty()) return 0;
  Points3 mid(crossing.size(), 3);
  for (size_t c = 0; c < crossing.size(); ++c) {
    const int k = crossing[c];
    mid.row(static_cast<Eigen::Index>(c)) = from.row(k) + 0.5 * (enter.t(k) + 1 - leave.t(k)) * dir.row(k);
  }
  const ClosestPoints inside = body.closest(mid, /*smooth_normals=*/false);
  long threaded = 0;
  for (Eigen::Index c = 0; c < mid.rows(); ++c) threaded += inside.sdist(c) < -depth;
  return threaded;
}

void add_threaded(long edges, int t, ResolutionValidity& r) {
  r.threaded_frames += edges > 0;
  if (edges > r.max_threaded_edges) {
    r.max_threaded_edges = edges;
    r.max_threaded_frame = t;
  }
}

void add_penetration(const Depths& d, int t, double limit, bool body_crossing, ResolutionValidity& r) {
  if (d.all > r.max_penetration) {  // the frame stays -1 while nothing penetrates
    r.max_penetration = d.all;
    r.max_penetration_frame = t;
  }
  if (d.free > r.max_penetration_free) {
    r.max_penetration_free = d.free;
    r.max_penetration_free_frame = t;
  }
  r.frames_over_limit += d.all > limit;
  r.frames_over_limit_free += d.free > limit;
  r.pinch_frames += d.pinched > limit;
  r.pinch_frames_in_body_crossings += body_crossing && d.pinched > limit;
}

double mean_distance(const Points3& a, const Points3& b) {
  return a.rows() > 0 ? (a - b).rowwise().norm().mean() : 0.0;
}

}  // namespace

// Two body faces intersect (CGAL) whose vertices were all farther than sep apart in the first
// frame, rest: two parts, one inside the other (validity.hpp).
std::vector<std::pair<int, int>> body_crossing_pairs(const Points3& V, const Faces& F, const Points3& rest,
                                                     double sep) {
  const SelfIntersections si = self_intersections(V, F, /*list_pairs=*/true);
  const double sep2 = sep * sep;
  std::vector<std::pair<int, int>> out;
  for (const auto& [f, g] : si.list) {
    bool apart = true;
    for (int a = 0; a < 3 && apart; ++a)
      for (int b = 0; b < 3 && apart; ++b) apart = (rest.row(F(f, a)) - rest.row(F(g, b))).squaredNorm() > sep2;
    if (apart) out.emplace_back(f, g);
  }
  return out;
}

bool body_crosses_itself(const Points3& V, const Faces& F, const Points3& rest, double sep) {
  return !body_crossing_pairs(V, F, rest, sep).empty();
}

std::string validity_per_frame_csv(const ValidityFigures& v) {
  std::string s =
      "frame,lr_pairs,hr_pairs,lr_depth_outside_pinches_mm,hr_depth_outside_pinches_mm,agreement_mm,lr_threaded,"
      "hr_threaded,body_crosses_itself\n";
  char buf[160];
  for (size_t t = 0; t < v.per_frame.size(); ++t) {
    const FrameValidity& f = v.per_frame[t];
    std::snprintf(buf, sizeof buf, "%zu,%ld,%ld,%.2f,%.2f,%.2f,%ld,%ld,%d\n", t, f.lr_pairs, f.hr_pairs,
                  1e3 * f.lr_depth, 1e3 * f.hr_depth, 1e3 * f.agreement, f.lr_threaded, f.hr_threaded,
                  f.body_crossing ? 1 : 0);
    s += buf;
  }
  return s;
}

double ValidityFigures::strain_ratio_u() const { return ratio(hr.strain.E_u, lr.strain.E_u); }
double ValidityFigures::strain_ratio_v() const { return ratio(hr.strain.E_v, lr.strain.E_v); }
double ValidityFigures::strain_ratio_uv() const { return ratio(hr.strain.E_uv, lr.strain.E_uv); }
double ValidityFigures::stretched_ratio_u() const { return ratio(hr.strain.E_u_stretched, lr.strain.E_u_stretched); }
double ValidityFigures::stretched_ratio_v() const { return ratio(hr.strain.E_v_stretched, lr.strain.E_v_stretched); }

ValidityFigures measure_validity(const Dataset& d, const ValidityOptions& opt, const ProgressFn& progress) {
  if (opt.intersection_stride < 1) fail("validity", "intersection stride must be >= 1");
  if (!(opt.penetration_limit >= 0)) fail("validity", "penetration limit must be >= 0");
  if (!(opt.pinch_reach > 0) || !(opt.pinch_separation > 0)) fail("validity", "pinch reach and separation must be > 0");
  if (!(opt.pinch_gap >= 0)) fail("validity", "pinch gap must be >= 0");
  if (!(opt.tear_stretch > 1)) fail("validity", "tear stretch must be > 1");
  if (!(opt.threaded_depth > 0)) fail("validity", "threaded depth must be > 0");
  const int T = static_cast<int>(d.lr_frames.size());
  if (T == 0 || d.hr_frames.size() != d.lr_frames.size())
    fail("validity", "the dataset has no frames (or LR/HR counts differ)");
  ValidityFigures v;
  v.frames = T;
  v.intersection_stride = opt.intersection_stride;
  v.penetration_limit = opt.penetration_limit;
  v.tear_stretch = opt.tear_stretch;
  v.threaded_depth = opt.threaded_depth;
  v.pinch_gap = opt.pinch_gap;
  v.lr.faces = static_cast<int>(d.lr.F.rows());
  v.hr.faces = static_cast<int>(d.hr.F.rows());
  v.body_measured = opt.body && d.has_body();
  v.agreement_rest = mean_distance(d.hr.V, upsample(d.corr, d.lr.V));
  v.per_frame.assign(T, FrameValidity{});

  const int steps = T + 2;  // the per-frame figures, then the LR and the HR self-intersections
  std::unique_ptr<BodyQuery> body;
  const Pairs lr_edges = unique_edges(d.lr.F), hr_edges = unique_edges(d.hr.F);
  std::set<int> lr_torn, hr_torn;  // cloth vertices of edges longer than tear_stretch, over the clip
  for (int t = 0; t < T; ++t) {
    auto strain = [&](const GarmentMesh& g, const Points3& X, ResolutionValidity& r, std::set<int>& torn) {
      const StrainEnergies e = strain_energies(g, X);
      r.strain.E_u += e.E_u / T;
      r.strain.E_v += e.E_v / T;
      r.strain.E_uv += e.E_uv / T;
      r.strain.E_u_stretched += e.E_u_stretched / T;
      r.strain.E_v_stretched += e.E_v_stretched / T;
      const double stretch = max_edge_stretch(g, X);
      if (stretch > opt.tear_stretch) {
        ++r.torn_frames;
        for (int u : overstretched_vertices(g, X, opt.tear_stretch)) torn.insert(u);
      }
      if (stretch > r.max_edge_stretch || r.max_edge_stretch_frame < 0) {
        r.max_edge_stretch = stretch;
        r.max_edge_stretch_frame = t;
      }
      r.mean_curvature += wrinkle_measure(X, g.F).mean_curvature / T;
    };
    strain(d.lr, d.lr_frames[t], v.lr, lr_torn);
    strain(d.hr, d.hr_frames[t], v.hr, hr_torn);
    const Points3 up = upsample(d.corr, d.lr_frames[t]);
    v.upsampled_mean_curvature += wrinkle_measure(up, d.hr.F).mean_curvature / T;
    const double agree = mean_distance(d.hr_frames[t], up);
    const Points3 hr_coarse = at_lr_scale(d.corr, d.hr_frames[t]);
    v.agreement_lr_scale += mean_distance(hr_coarse, up) / T;
    v.agreement_finer += mean_distance(d.hr_frames[t], hr_coarse) / T;
    v.per_frame[t].agreement = agree;
    v.agreement_mean += agree / T;
    if (agree > v.agreement_max || v.agreement_max_frame < 0) {
      v.agreement_max = agree;
      v.agreement_max_frame = t;
    }
    if (v.body_measured) {
      const TriMesh mesh{d.body_frames[t], d.body_faces};
      if (!body)
        body = std::make_unique<BodyQuery>(mesh);
      else
        body->update(d.body_frames[t]);
      const Points3& rest = d.body_frames[0];
      const bool crossing = body_crosses_itself(d.body_frames[t], d.body_faces, rest, opt.pinch_separation);
      v.body_crossing_frames += crossing;
      v.per_frame[t].body_crossing = crossing;
      // One closest-point query per resolution serves the penetration and the threaded edges.
      const ClosestPoints lr_cp = body->closest(d.lr_frames[t], /*smooth_normals=*/false),
                          hr_cp = body->closest(d.hr_frames[t], /*smooth_normals=*/false);
      const Depths lr = penetration(*body, lr_cp, rest, d.lr_frames[t], opt),
                   hr = penetration(*body, hr_cp, rest, d.hr_frames[t], opt);
      add_penetration(lr, t, opt.penetration_limit, crossing, v.lr);
      add_penetration(hr, t, opt.penetration_limit, crossing, v.hr);
      v.per_frame[t].lr_depth = lr.free;
      v.per_frame[t].hr_depth = hr.free;
      v.per_frame[t].lr_threaded = threaded_edges(*body, lr_cp, d.lr_frames[t], lr_edges, opt.threaded_depth);
      v.per_frame[t].hr_threaded = threaded_edges(*body, hr_cp, d.hr_frames[t], hr_edges, opt.threaded_depth);
      add_threaded(v.per_frame[t].lr_threaded, t, v.lr);
      add_threaded(v.per_frame[t].hr_threaded, t, v.hr);
    }
    if (progress) progress(t + 1, steps);
  }
  v.lr.torn_vertices = static_cast<int>(lr_torn.size());
  v.hr.torn_vertices = static_cast<int>(hr_torn.size());
  measure_intersections(d.lr_frames, d.lr.F, d.lr.layer, opt.intersection_stride, v.lr, v.per_frame,
                        &FrameValidity::lr_pairs, &FrameValidity::lr_layers);
  if (progress) progress(T + 1, steps);
  measure_intersections(d.hr_frames, d.hr.F, d.hr.layer, opt.intersection_stride, v.hr, v.per_frame,
                        &FrameValidity::hr_pairs, &FrameValidity::hr_layers);
  count_knots(v.per_frame, &FrameValidity::lr_pairs, &FrameValidity::lr_layers, v.body_measured, v.lr);
  count_knots(v.per_frame, &FrameValidity::hr_pairs, &FrameValidity::hr_layers, v.body_measured, v.hr);
  if (progress) progress(steps, steps);
  return v;
}

BodyDepths body_depths(const Dataset& d, int t, const Points3& X, const ValidityOptions& opt) {
  if (!d.has_body()) fail("validity", "the dataset has no body");
  if (t < 0 || t >= static_cast<int>(d.body_frames.size()))
    fail("validity", "frame " + std::to_string(t) + " out of range");
  const BodyQuery body(TriMesh{d.body_frames[t], d.body_faces});
  const ClosestPoints cp = body.closest(X, /*smooth_normals=*/false);
  BodyDepths out;
  out.depth.resize(X.rows());
  out.pinched.resize(X.rows());
  for (long i = 0; i < X.rows(); ++i) {
    const VertexDepth v = vertex_depth(body, cp, d.body_frames[0], X, i, opt);
    out.depth[i] = v.depth;
    out.pinched[i] = v.pinched;
  }
  return out;
}

// ---------------------------------------------------------------- manifest JSON

namespace {

nlohmann::json resolution_json(const ResolutionValidity& r, bool body) {
  nlohmann::json j = {{"faces", r.faces},
                      {"self_intersection",
                       {{"frames_checked", r.si_frames},
                        {"clean_frames", r.si_clean_frames},
                        {"clean_fraction", r.si_clean_fraction()},
                        {"median_pairs", r.si_median_pairs},
                        {"max_pairs", r.si_max_pairs},
                        {"max_pairs_frame", r.si_max_frame},
                        {"degenerate_faces", r.si_degenerate_faces},
                        {"skipped_faces", r.si_skipped_faces},
                        {"knots", r.si_knots},
                        {"longest_knot",
                         {{"first_frame", r.si_longest_knot_first},
                          {"last_frame", r.si_longest_knot_last},
                          {"layers", r.si_longest_knot_layers}}}}},
                      {"strain",
                       {{"E_u", r.strain.E_u},
                        {"E_v", r.strain.E_v},
                        {"E_uv", r.strain.E_uv},
                        {"E_u_stretched", r.strain.E_u_stretched},
                        {"E_v_stretched", r.strain.E_v_stretched},
                        {"max_edge_stretch", r.max_edge_stretch},
                        {"max_edge_stretch_frame", r.max_edge_stretch_frame},
                        {"torn_frames", r.torn_frames},
                        {"torn_vertices", r.torn_vertices}}},
                      {"mean_curvature_1_m", r.mean_curvature}};
  if (!body) return j;
  j["self_intersection"]["knots_from_body_crossings"] = r.si_knots_from_body_crossings;
  j["self_intersection"]["knot_frames_from_body_crossings"] = r.si_knot_frames_from_body_crossings;
  j["body"] = {{"max_penetration_m", r.max_penetration},
               {"max_penetration_frame", r.max_penetration_frame},
               {"frames_over_limit", r.frames_over_limit},
               {"max_penetration_outside_pinches_m", r.max_penetration_free},
               {"max_penetration_outside_pinches_frame", r.max_penetration_free_frame},
               {"frames_over_limit_outside_pinches", r.frames_over_limit_free},
               {"pinch_frames", r.pinch_frames},
               {"pinch_frames_in_body_crossings", r.pinch_frames_in_body_crossings},
               {"threaded_frames", r.threaded_frames},
               {"max_threaded_edges", r.max_threaded_edges},
               {"max_threaded_frame", r.max_threaded_frame}};
  return j;
}

template <class T> T take(const nlohmann::json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) fail("validity", "manifest figures: missing key '" + where + key + "'");
  try {
    return j.at(key).get<T>();
  } catch (const std::exception&) {
    fail("validity", "manifest figures: key '" + where + key + "' has the wrong type");
  }
}

ResolutionValidity resolution_from_json(const nlohmann::json& j, bool body, const std::string& where) {
  ResolutionValidity r;
  r.faces = take<int>(j, "faces", where);
  const auto si = take<nlohmann::json>(j, "self_intersection", where);
  const std::string w = where + "self_intersection.";
  r.si_frames = take<int>(si, "frames_checked", w);
  r.si_clean_frames = take<int>(si, "clean_frames", w);
  r.si_median_pairs = take<double>(si, "median_pairs", w);
  r.si_max_pairs = take<long>(si, "max_pairs", w);
  r.si_max_frame = take<int>(si, "max_pairs_frame", w);
  r.si_degenerate_faces = take<long>(si, "degenerate_faces", w);
  r.si_skipped_faces = take<long>(si, "skipped_faces", w);
  // Manifests written before knots were counted: not measured.
  r.si_knots = si.contains("knots") ? take<int>(si, "knots", w) : -1;
  r.si_knots_from_body_crossings =
      si.contains("knots_from_body_crossings") ? take<int>(si, "knots_from_body_crossings", w) : -1;
  r.si_knot_frames_from_body_crossings =
      si.contains("knot_frames_from_body_crossings") ? take<int>(si, "knot_frames_from_body_crossings", w) : -1;
  if (si.contains("longest_knot")) {
    const auto k = take<nlohmann::json>(si, "longest_knot", w);
    r.si_longest_knot_first = take<int>(k, "first_frame", w + "longest_knot.");
    r.si_longest_knot_last = take<int>(k, "last_frame", w + "longest_knot.");
    r.si_longest_knot_layers = take<std::array<int, 2>>(k, "layers", w + "longest_knot.");
  }
  const auto st = take<nlohmann::json>(j, "strain", where);
  r.strain.E_u = take<double>(st, "E_u", where + "strain.");
  r.strain.E_v = take<double>(st, "E_v", where + "strain.");
  r.strain.E_uv = take<double>(st, "E_uv", where + "strain.");
  // Manifests written before E_u was split: not measured.
  const bool split = st.contains("E_u_stretched");
  r.strain.E_u_stretched =
      split ? take<double>(st, "E_u_stretched", where + "strain.") : std::numeric_limits<double>::quiet_NaN();
  r.strain.E_v_stretched =
      split ? take<double>(st, "E_v_stretched", where + "strain.") : std::numeric_limits<double>::quiet_NaN();
  // Manifests written before torn cloth was counted: not measured.
  if (st.contains("torn_frames")) {
    r.max_edge_stretch = take<double>(st, "max_edge_stretch", where + "strain.");
    r.max_edge_stretch_frame = take<int>(st, "max_edge_stretch_frame", where + "strain.");
    r.torn_frames = take<int>(st, "torn_frames", where + "strain.");
  } else {
    r.torn_frames = -1;
  }
  r.torn_vertices = st.contains("torn_vertices") ? take<int>(st, "torn_vertices", where + "strain.") : -1;
  r.mean_curvature = take<double>(j, "mean_curvature_1_m", where);
  if (body) {
    const auto b = take<nlohmann::json>(j, "body", where);
    r.max_penetration = take<double>(b, "max_penetration_m", where + "body.");
    r.max_penetration_frame = take<int>(b, "max_penetration_frame", where + "body.");
    r.frames_over_limit = take<int>(b, "frames_over_limit", where + "body.");
    // Manifests written before pinches were told apart count every penetration as free.
    const bool split = b.contains("pinch_frames");
    r.max_penetration_free = split ? take<double>(b, "max_penetration_outside_pinches_m", where + "body.") : r.max_penetration;
    r.max_penetration_free_frame =
        split ? take<int>(b, "max_penetration_outside_pinches_frame", where + "body.") : r.max_penetration_frame;
    r.frames_over_limit_free = split ? take<int>(b, "frames_over_limit_outside_pinches", where + "body.") : r.frames_over_limit;
    r.pinch_frames = split ? take<int>(b, "pinch_frames", where + "body.") : 0;
    // ... and before the body's own crossings were counted: unknown.
    r.pinch_frames_in_body_crossings =
        b.contains("pinch_frames_in_body_crossings") ? take<int>(b, "pinch_frames_in_body_crossings", where + "body.") : -1;
    // ... and before threaded cloth was counted: not measured.
    if (b.contains("threaded_frames")) {
      r.threaded_frames = take<int>(b, "threaded_frames", where + "body.");
      r.max_threaded_edges = take<long>(b, "max_threaded_edges", where + "body.");
      r.max_threaded_frame = take<int>(b, "max_threaded_frame", where + "body.");
    } else {
      r.threaded_frames = -1;
    }
  }
  return r;
}

}  // namespace

nlohmann::json validity_to_json(const ValidityFigures& v) {
  nlohmann::json j = {{"frames", v.frames},
                      {"intersection_stride", v.intersection_stride},
                      {"penetration_limit_m", v.penetration_limit},
                      {"tear_stretch", v.tear_stretch},
                      {"threaded_depth_m", v.threaded_depth},
                      {"pinch_gap_m", v.pinch_gap},
                      {"body_measured", v.body_measured},
                      {"lr", resolution_json(v.lr, v.body_measured)},
                      {"hr", resolution_json(v.hr, v.body_measured)},
                      {"agreement_m",
                       {{"mean", v.agreement_mean},
                        {"max_frame_mean", v.agreement_max},
                        {"max_frame", v.agreement_max_frame},
                        {"rest", v.agreement_rest},
                        {"lr_scale_mean", v.agreement_lr_scale},
                        {"finer_mean", v.agreement_finer}}},
                      {"lr_upsampled_mean_curvature_1_m", v.upsampled_mean_curvature}};
  if (v.body_measured) j["body_crossing_frames"] = v.body_crossing_frames;
  return j;
}

ValidityFigures validity_from_json(const nlohmann::json& j) {
  ValidityFigures v;
  v.frames = take<int>(j, "frames", "");
  v.intersection_stride = take<int>(j, "intersection_stride", "");
  v.penetration_limit = take<double>(j, "penetration_limit_m", "");
  if (j.contains("tear_stretch")) v.tear_stretch = take<double>(j, "tear_stretch", "");
  if (j.contains("threaded_depth_m")) v.threaded_depth = take<double>(j, "threaded_depth_m", "");
  v.pinch_gap = j.contains("pinch_gap_m") ? take<double>(j, "pinch_gap_m", "") : 0.0;
  v.body_measured = take<bool>(j, "body_measured", "");
  v.body_crossing_frames = j.contains("body_crossing_frames") ? take<int>(j, "body_crossing_frames", "") : -1;
  v.lr = resolution_from_json(take<nlohmann::json>(j, "lr", ""), v.body_measured, "lr.");
  v.hr = resolution_from_json(take<nlohmann::json>(j, "hr", ""), v.body_measured, "hr.");
  const auto a = take<nlohmann::json>(j, "agreement_m", "");
  v.agreement_mean = take<double>(a, "mean", "agreement_m.");
  v.agreement_max = take<double>(a, "max_frame_mean", "agreement_m.");
  v.agreement_max_frame = take<int>(a, "max_frame", "agreement_m.");
  v.agreement_rest = take<double>(a, "rest", "agreement_m.");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  v.agreement_lr_scale = a.contains("lr_scale_mean") ? take<double>(a, "lr_scale_mean", "agreement_m.") : nan;
  v.agreement_finer = a.contains("finer_mean") ? take<double>(a, "finer_mean", "agreement_m.") : nan;
  v.upsampled_mean_curvature = take<double>(j, "lr_upsampled_mean_curvature_1_m", "");
  return v;
}

// ---------------------------------------------------------------- table

std::string validity_table(const ValidityFigures& v) {
  std::string s;
  char buf[256];
  auto line = [&](const char* fmt, auto... args) {
    std::snprintf(buf, sizeof buf, fmt, args...);
    s += buf;
  };
  auto ratio_str = [](double r) {
    char b[32];
    if (std::isnan(r)) return std::string("-");
    std::snprintf(b, sizeof b, "%.2fx", r);
    return std::string(b);
  };
  const std::string every =
      v.intersection_stride == 1 ? "every frame" : "1 frame in " + std::to_string(v.intersection_stride);
  line("validity over %d frames (self-intersections on %s: %d checked)\n", v.frames, every.c_str(), v.hr.si_frames);
  line("  %-40s %14s %14s %9s\n", "", "LR", "HR", "HR/LR");
  line("  %-40s %14d %14d\n", "faces", v.lr.faces, v.hr.faces);
  line("  %-40s %13.1f%% %13.1f%%\n", "self-intersection: frames with 0 pairs", 100 * v.lr.si_clean_fraction(),
       100 * v.hr.si_clean_fraction());
  line("  %-40s %14.1f %14.1f\n", "self-intersection: median pairs", v.lr.si_median_pairs, v.hr.si_median_pairs);
  line("  %-40s %8ld (f%3d) %8ld (f%3d)\n", "self-intersection: max pairs (frame)", v.lr.si_max_pairs,
       v.lr.si_max_frame, v.hr.si_max_pairs, v.hr.si_max_frame);
  if (v.lr.si_knots >= 0 && v.hr.si_knots >= 0)
    line("  %-40s %14d %14d\n", "self-intersection: knots (runs of frames)", v.lr.si_knots, v.hr.si_knots);
  if (v.body_crossing_frames >= 0 && v.lr.si_knots_from_body_crossings >= 0 && v.hr.si_knots_from_body_crossings >= 0) {
    auto share = [](const ResolutionValidity& r) {
      char b[48];
      std::snprintf(b, sizeof b, "%d (%d fr)", r.si_knots_from_body_crossings, r.si_knot_frames_from_body_crossings);
      return std::string(b);
    };
    line("  %-40s %14s %14s\n", "  begun where the body crosses itself", share(v.lr).c_str(), share(v.hr).c_str());
  }
  if (v.lr.si_longest_knot_first >= 0 || v.hr.si_longest_knot_first >= 0) {
    // "47-79, L1-L2": the longest knot's frames and the layers where it began
    auto knot = [](const ResolutionValidity& r) {
      if (r.si_longest_knot_first < 0) return std::string("-");
      char b[64];
      std::snprintf(b, sizeof b, "%d-%d", r.si_longest_knot_first, r.si_longest_knot_last);
      std::string s = b;
      if (r.si_longest_knot_layers[0] >= 0) {
        std::snprintf(b, sizeof b, ", L%d-L%d", r.si_longest_knot_layers[0], r.si_longest_knot_layers[1]);
        s += b;
      }
      return s;
    };
    line("  %-40s %14s %14s\n", "  longest: frames, layers where it began", knot(v.lr).c_str(), knot(v.hr).c_str());
  }
  if (v.lr.si_degenerate_faces + v.hr.si_degenerate_faces + v.lr.si_skipped_faces + v.hr.si_skipped_faces > 0)
    line("  %-40s %6ld / %5ld %6ld / %5ld\n", "  degenerate / non-manifold faces skipped", v.lr.si_degenerate_faces,
         v.lr.si_skipped_faces, v.hr.si_degenerate_faces, v.hr.si_skipped_faces);
  line("  %-40s %14.5f %14.5f %9s\n", "strain: mean E_u", v.lr.strain.E_u, v.hr.strain.E_u,
       ratio_str(v.strain_ratio_u()).c_str());
  line("  %-40s %14.5f %14.5f %9s\n", "strain: mean E_v", v.lr.strain.E_v, v.hr.strain.E_v,
       ratio_str(v.strain_ratio_v()).c_str());
  line("  %-40s %14.5f %14.5f %9s\n", "strain: mean E_uv", v.lr.strain.E_uv, v.hr.strain.E_uv,
       ratio_str(v.strain_ratio_uv()).c_str());
  if (!std::isnan(v.lr.strain.E_u_stretched) && !std::isnan(v.hr.strain.E_u_stretched)) {
    line("  %-40s %14.5f %14.5f %9s\n", "  of E_u: stretched fibres", v.lr.strain.E_u_stretched,
         v.hr.strain.E_u_stretched, ratio_str(v.stretched_ratio_u()).c_str());
    line("  %-40s %14.5f %14.5f %9s\n", "  of E_v: stretched fibres", v.lr.strain.E_v_stretched,
         v.hr.strain.E_v_stretched, ratio_str(v.stretched_ratio_v()).c_str());
  }
  if (v.lr.torn_frames >= 0 && v.hr.torn_frames >= 0) {
    auto longest = [](const ResolutionValidity& r) {
      char b[48];
      std::snprintf(b, sizeof b, "%.2fx (f%3d)", r.max_edge_stretch, r.max_edge_stretch_frame);
      return std::string(b);
    };
    line("  %-40s %14s %14s\n", "strain: longest edge / pattern (frame)", longest(v.lr).c_str(), longest(v.hr).c_str());
    char label[64];
    std::snprintf(label, sizeof label, "strain: frames with an edge > %gx", v.tear_stretch);
    line("  %-40s %14d %14d\n", label, v.lr.torn_frames, v.hr.torn_frames);
    if (v.lr.torn_vertices >= 0 && v.hr.torn_vertices >= 0)
      line("  %-40s %14d %14d\n", "  cloth vertices on those edges", v.lr.torn_vertices, v.hr.torn_vertices);
  }
  if (v.body_measured) {
    auto depth = [](const ResolutionValidity& r) {
      char b[48];
      if (r.max_penetration_frame < 0) return std::string("none");
      std::snprintf(b, sizeof b, "%.1f (f%3d)", 1e3 * r.max_penetration, r.max_penetration_frame);
      return std::string(b);
    };
    auto depth_free = [](const ResolutionValidity& r) {
      char b[48];
      if (r.max_penetration_free_frame < 0) return std::string("none");
      std::snprintf(b, sizeof b, "%.1f (f%3d)", 1e3 * r.max_penetration_free, r.max_penetration_free_frame);
      return std::string(b);
    };
    const std::string mm = std::to_string(static_cast<int>(std::lround(1e3 * v.penetration_limit))) + " mm";
    line("  %-40s %14s %14s\n", "body: max penetration, mm (frame)", depth(v.lr).c_str(), depth(v.hr).c_str());
    line("  body: frames deeper than %-15s %14d %14d\n", mm.c_str(), v.lr.frames_over_limit, v.hr.frames_over_limit);
    line("  %-40s %14s %14s\n", "body: outside pinches: max, mm (frame)", depth_free(v.lr).c_str(),
         depth_free(v.hr).c_str());
    line("  body: outside pinches: frames > %-7s %14d %14d\n", mm.c_str(), v.lr.frames_over_limit_free,
         v.hr.frames_over_limit_free);
    line("  body: pinch frames (part/crease > %-7s%14d %14d\n", (mm + ")").c_str(), v.lr.pinch_frames,
         v.hr.pinch_frames);
    if (v.body_crossing_frames >= 0) {
      line("  %-40s %14d\n", "body: frames it crosses itself (2 parts)", v.body_crossing_frames);
      line("  %-40s %14d %14d\n", "  pinch frames among them", v.lr.pinch_frames_in_body_crossings,
           v.hr.pinch_frames_in_body_crossings);
    }
    if (v.lr.threaded_frames >= 0 && v.hr.threaded_frames >= 0) {
      auto most = [](const ResolutionValidity& r) {
        char b[48];
        if (r.max_threaded_frame < 0) return std::string("none");
        std::snprintf(b, sizeof b, "%ld (f%3d)", r.max_threaded_edges, r.max_threaded_frame);
        return std::string(b);
      };
      line("  %-40s %14d %14d\n", "body: frames with cloth threaded on it", v.lr.threaded_frames, v.hr.threaded_frames);
      line("  %-40s %14s %14s\n", "  most edges through the body (frame)", most(v.lr).c_str(), most(v.hr).c_str());
    }
  } else {
    line("  %-40s %14s %14s\n", "body: penetration", "not measured", "(no body)");
  }
  line("  %-40s %14.3f %14.3f\n", "wrinkles: mean |mean curvature|, 1/m", v.lr.mean_curvature, v.hr.mean_curvature);
  line("  %-40s %14.3f %14s %9s\n", "  LR upsampled to HR topology", v.upsampled_mean_curvature, "",
       ratio_str(ratio(v.hr.mean_curvature, v.upsampled_mean_curvature)).c_str());
  line("  agreement |HR - LR upsampled|, mm: mean %.1f over the clip, worst frame %.1f (f%d), rest %.2f\n",
       1e3 * v.agreement_mean, 1e3 * v.agreement_max, v.agreement_max_frame, 1e3 * v.agreement_rest);
  if (std::isfinite(v.agreement_lr_scale))
    line("    by scale (HR downsampled and upsampled: S), mm: drape |S - LR upsampled| %.1f, wrinkles |HR - S| %.1f\n",
         1e3 * v.agreement_lr_scale, 1e3 * v.agreement_finer);
  return s;
}

}  // namespace gdsr

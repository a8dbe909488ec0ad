// SelfCollision::project: one Gauss-Seidel pass over the self-contact pairs, in their fixed
// order. From kTwoThreadProjectPairs pairs it runs in two phases with the sequential result bit
// for bit: every pair is first evaluated on two threads at the pass's starting positions; then,
// in order, a pair none of whose vertices an earlier push has moved takes that evaluation (the
// same inputs give the same result), and the pushes and the pairs next to them are computed
// again on the moved positions. Most pairs are apart by their thickness and push nothing, and
// on the HR t-shirt a pass redoes 14% of them. Where pushes crowd (cloth pressed together,
// dozens of pairs per vertex) nearly every pair is redone and the two phases cost 1.5 passes:
// after a pass that redid more than kMostRedone of its pairs the passes run in order, and one
// in kRetryEvery tries the two phases again. Either way the result is the same.
#include "gdsr/sim/cloth_self_collision.hpp"

#include "gdsr/sim/contact_geometry.hpp"

#include <omp.h>

#include <algorithm>

namespace sim {

using gdsr::Points3;
using gdsr::Vec3;

namespace {

constexpr double kInside = -1e-3;    // barycentric tolerance: a vertex on a shared edge is guarded by both faces
constexpr double kEdgeEnd = 1e-3;    // edge parameter tolerance for an interior edge-edge closest point
constexpr double kMostRedone = 0.4;  // the two phases' break-even is 0.5, less their overheads
constexpr int kRetryEvery = 8;

}  // namespace

bool SelfCollision::project_pair(const Points3& x, const ProjectLimits& l, VT& c, PairPush& out) const {
  const int ia = F_(c.f, 0), ib = F_(c.f, 1), ic = F_(c.f, 2);
  const Vec3 p = x.row(c.v), a = x.row(ia), b = x.row(ib), cc = x.row(ic);
  Vec3 bary, n;
  double dist = 0;
  if (!project_on_triangle(p, a, b, cc, bary, n, dist)) return false;
  const bool free = tangled_on_both_sides(c) || -c.side * dist > c.reach;
  if (free || bary.minCoeff() < kInside) {  // crossing the plane is legal here: follow the geometry
    if (dist != 0) c.side = dist > 0 ? 1 : -1;
    return false;
  }
  const double C = std::max(c.side * dist - l.thickness, -l.max_crossed_push);
  if (C >= 0) return false;
  const std::vector<double>& winv = *l.winv;
  const double wp = winv[c.v], wa = winv[ia], wb = winv[ib], wc = winv[ic];
  const double wsum = std::max(wp + bary.x() * bary.x() * wa + bary.y() * bary.y() * wb + bary.z() * bary.z() * wc,
                               l.min_mass_share * std::max({wp, wa, wb, wc}));
  if (!(wsum > 0)) return false;
  const Vec3 dir = (-C / wsum * c.side) * n;
  out = {{c.v, ia, ib, ic},
         {wp * dir, -(wa * bary.x() * dir), -(wb * bary.y() * dir), -(wc * bary.z() * dir)},
         c.side * dist < 0};
  return true;
}

bool SelfCollision::project_pair(const Points3& x, const ProjectLimits& l, EE& c, PairPush& out) const {
  const int i0 = edges_[c.a][0], i1 = edges_[c.a][1], j0 = edges_[c.b][0], j1 = edges_[c.b][1];
  const Vec3 p1 = x.row(i0), q1 = x.row(i1), p2 = x.row(j0), q2 = x.row(j1);
  double s = 0, t = 0;
  closest_segments(p1, q1, p2, q2, s, t);
  const Vec3 d = (p1 + s * (q1 - p1)) - (p2 + t * (q2 - p2));
  const double len = d.norm();
  const Vec3 dir(c.dir[0], c.dir[1], c.dir[2]);
  const bool free = tangled_on_both_sides(c) || -d.dot(dir) > c.reach;
  const bool interior = s > kEdgeEnd && s < 1 - kEdgeEnd && t > kEdgeEnd && t < 1 - kEdgeEnd;
  const double along = d.dot(dir);
  if (free || !interior || dir.squaredNorm() == 0 || (along > 0 && len >= l.thickness)) {
    // Free to move (or apart on the remembered side): the side follows the geometry.
    if (len > 0) c.set_dir(d / len);
    return false;
  }
  // Same side but too close: push along the current separation; crossed: push back
  // along the remembered side.
  Vec3 n = dir;
  double C = std::max(along - l.thickness, -l.max_crossed_push);
  if (along > 0 && len > 0) {
    n = d / len;
    C = len - l.thickness;
    c.set_dir(n);
  }
  const std::vector<double>& winv = *l.winv;
  const double w0 = winv[i0], w1 = winv[i1], w2 = winv[j0], w3 = winv[j1];
  const double wsum = std::max((1 - s) * (1 - s) * w0 + s * s * w1 + (1 - t) * (1 - t) * w2 + t * t * w3,
                               l.min_mass_share * std::max({w0, w1, w2, w3}));
  if (!(wsum > 0)) return false;
  const Vec3 step = (-C / wsum) * n;
  out = {{i0, i1, j0, j1}, {w0 * (1 - s) * step, w1 * s * step, -(w2 * (1 - t) * step), -(w3 * t * step)}, along <= 0};
  return true;
}

template <class Pair>
int SelfCollision::project_in_order(Points3& x, const ProjectLimits& l, std::vector<Pair>& pairs) {
  int pushed = 0;
  PairPush push;
  for (Pair& c : pairs)
    if (project_pair(x, l, c, push)) {
      if (push.crossed && refuse_crossing_pushes_ && body_touched(push) && refuse_crossing_push(x, c, push)) continue;
      push.apply(x);
      ++pushed;
      crossed_pushed_ += push.crossed;
    }
  return pushed;
}

template <class Pair> int SelfCollision::project_speculated(Points3& x, const ProjectLimits& l,
                                                            std::vector<Pair>& pairs, std::vector<Pair>& evaluated,
                                                            const std::vector<char>& pushes, size_t& redone) {
  int pushed = 0;
  PairPush push;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!pushes[i] && !touches(pairs[i])) continue;  // evaluated[i] stands
    ++redone;
    Pair& c = evaluated[i] = pairs[i];
    if (project_pair(x, l, c, push)) {
      if (push.crossed && refuse_crossing_pushes_ && body_touched(push) && refuse_crossing_push(x, c, push)) continue;
      push.apply(x);
      mark_moved(push);
      ++pushed;
      crossed_pushed_ += push.crossed;
    }
  }
  pairs.swap(evaluated);
  return pushed;
}

bool SelfCollision::faces_cross(const Points3& x, const int* fa, int na, const int* fb, int nb) const {
  auto shares = [&](int f, int g) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (F_(f, i) == F_(g, j)) return true;
    return false;
  };
  auto edge_crosses = [&](int f, int g) {  // an edge of face f through face g
    const Vec3 a = x.row(F_(g, 0)), b = x.row(F_(g, 1)), c = x.row(F_(g, 2));
    for (int i = 0; i < 3; ++i)
      if (segment_crosses_triangle(x.row(F_(f, i)), x.row(F_(f, (i + 1) % 3)), a, b, c)) return true;
    return false;
  };
  for (int i = 0; i < na; ++i)
    for (int j = 0; j < nb; ++j)
      if (fa[i] >= 0 && fb[j] >= 0 && !shares(fa[i], fb[j]) &&
          (edge_crosses(fa[i], fb[j]) || edge_crosses(fb[j], fa[i])))
        return true;
  return false;
}

bool SelfCollision::faces_cross(const Points3& x, const VT& c) const {
  return faces_cross(x, vertex_faces_.items.data() + vertex_faces_.offsets[c.v], vertex_faces_.count(c.v), &c.f, 1);
}

bool SelfCollision::faces_cross(const Points3& x, const EE& c) const {
  return faces_cross(x, edge_faces_[c.a].data(), 2, edge_faces_[c.b].data(), 2);
}

template <class Pair> bool SelfCollision::push_makes_crossing(Points3& x, const Pair& c, const PairPush& push) const {
  if (faces_cross(x, c)) return false;  // crossing already: pushing back undoes it
  Vec3 kept[4];
  for (int k = 0; k < 4; ++k) kept[k] = x.row(push.v[k]);
  push.apply(x);
  const bool made = faces_cross(x, c);
  for (int k = 0; k < 4; ++k) x.row(push.v[k]) = kept[k].transpose();
  return made;
}

bool SelfCollision::refuse_crossing_push(Points3& x, VT& c, const PairPush& push) {
  if (!push_makes_crossing(x, c, push)) return false;
  c.side = static_cast<signed char>(-c.side);
  ++sides_corrected_;
  return true;
}

bool SelfCollision::refuse_crossing_push(Points3& x, EE& c, const PairPush& push) {
  if (!push_makes_crossing(x, c, push)) return false;
  const int i0 = edges_[c.a][0], i1 = edges_[c.a][1], j0 = edges_[c.b][0], j1 = edges_[c.b][1];
  double s = 0, t = 0;
  closest_segments(x.row(i0), x.row(i1), x.row(j0), x.row(j1), s, t);
  const Vec3 d = (x.row(i0) + s * (x.row(i1) - x.row(i0))) - (x.row(j0) + t * (x.row(j1) - x.row(j0)));
  if (d.norm() > 0) c.set_dir(d.normalized());
  ++sides_corrected_;
  return true;
}

bool SelfCollision::body_touched(const PairPush& push) const {
  if (!body_moved_) return true;
  for (int v : push.v)
    if ((*body_moved_)[v]) return true;
  return false;
}

void SelfCollision::mark_moved(const PairPush& push) {
  for (int v : push.v) {
    moved_v_[v] = 1;
    for (int k = vertex_faces_.offsets[v]; k < vertex_faces_.offsets[v + 1]; ++k) moved_f_[vertex_faces_.items[k]] = 1;
    for (int k = vertex_edges_.offsets[v]; k < vertex_edges_.offsets[v + 1]; ++k) moved_e_[vertex_edges_.items[k]] = 1;
  }
}

int SelfCollision::project(Points3& x, const std::vector<double>& winv, double thickness, double max_crossed_push,
                           double min_mass_share) {
  const ProjectLimits l{&winv, thickness, max_crossed_push, min_mass_share};
  const long nvt = static_cast<long>(vt_.size()), nee = static_cast<long>(ee_.size());
  const size_t pairs = static_cast<size_t>(nvt + nee);
  crossed_pushed_ = 0;
  sides_corrected_ = 0;
  if (pairs < kTwoThreadProjectPairs || omp_get_max_threads() < 2 ||
      (last_redone_share_ > kMostRedone && ++passes_in_order_ % kRetryEvery != 0))
    return project_in_order(x, l, vt_) + project_in_order(x, l, ee_);
  passes_in_order_ = 0;
  speculated_vt_.resize(nvt);
  speculated_ee_.resize(nee);
  pushes_vt_.resize(nvt);
  pushes_ee_.resize(nee);
#pragma omp parallel num_threads(2) if (omp_get_max_threads() > 1)  // (also checked above)
  {
    PairPush push;
#pragma omp for schedule(static) nowait
    for (long i = 0; i < nvt; ++i) {
      VT c = vt_[i];
      pushes_vt_[i] = project_pair(x, l, c, push);
      speculated_vt_[i] = c;
    }
#pragma omp for schedule(static)
    for (long i = 0; i < nee; ++i) {
      EE c = ee_[i];
      pushes_ee_[i] = project_pair(x, l, c, push);
      speculated_ee_[i] = c;
    }
  }
  moved_v_.assign(x.rows(), 0);
  moved_f_.assign(F_.rows(), 0);
  moved_e_.assign(edges_.size(), 0);
  size_t redone = 0;
  const int pushed = project_speculated(x, l, vt_, speculated_vt_, pushes_vt_, redone) +
                     project_speculated(x, l, ee_, speculated_ee_, pushes_ee_, redone);
  last_redone_share_ = static_cast<double>(redone) / static_cast<double>(pairs);
  return pushed;
}

}  // namespace sim

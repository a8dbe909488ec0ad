#include "gdsr/sim/cloth_solver.hpp"

#include "gdsr/error.hpp"

#include <Eigen/Geometry>
#include <nanoflann.hpp>
#include <omp.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace sim {

using gdsr::Points3;
using gdsr::Vec2;
using gdsr::Vec3;

namespace {

// A pin is pressed towards its home only by a part pushing it that way at more than this cosine:
// at a grazing angle a push of depth C moves the pin C over the cosine.
constexpr double kMinPinPress = 0.2;

// Per row of P: 1 where a finite row of Q lies within r of it (metres).
std::vector<char> points_near(const Points3& P, const Points3& Q, double r) {
  std::vector<char> near(P.rows(), 0);
  Points3 finite(Q.rows(), 3);
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < Q.rows(); ++i)
    if (Q.row(i).allFinite()) finite.row(n++) = Q.row(i);
  if (n == 0 || !(r > 0)) return near;
  finite.conservativeResize(n, 3);
  using Tree = nanoflann::KDTreeEigenMatrixAdaptor<Points3, 3, nanoflann::metric_L2_Simple>;
  Tree tree(3, std::cref(finite), 10);
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const double q[3] = {P(i, 0), P(i, 1), P(i, 2)};
    Eigen::Index nearest = 0;
    double d2 = 0;
    tree.index->knnSearch(q, 1, &nearest, &d2);
    near[i] = d2 <= r * r;
  }
  return near;
}

double cot(const Vec2& a, const Vec2& b) {  // cotangent of the angle between a and b
  const double c = a.dot(b);
  const double s = std::abs(a.x() * b.y() - a.y() * b.x());
  return c / std::max(s, 1e-12);
}

double uv_area(const gdsr::GarmentMesh& m, int f) {
  const Vec2 a = m.UV.row(m.FUV(f, 0)), b = m.UV.row(m.FUV(f, 1)), c = m.UV.row(m.FUV(f, 2));
  const Vec2 e1 = b - a, e2 = c - a;
  return 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
}

Vec3 face_normal(const Points3& V, const gdsr::Faces& F, int f) {
  const Vec3 a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  const Vec3 n = (b - a).cross(c - a);
  const double l = n.norm();
  return l > 0 ? Vec3(n / l) : Vec3(0, 1, 0);
}

Vec3 bary_point(const Points3& V, const gdsr::Faces& F, int f, const Vec3& b) {
  return b.x() * V.row(F(f, 0)).transpose() + b.y() * V.row(F(f, 1)).transpose() + b.z() * V.row(F(f, 2)).transpose();
}

}  // namespace

ClothSolver::ClothSolver(const Garment& g, const gdsr::Faces& body_F, const Points3& body_V0, const SimParams& p)
    : p_(p), F_(g.mesh.F), bodyF_(body_F), layer_(g.mesh.layer) {
  const auto& m = g.mesh;
  const int nv = static_cast<int>(m.V.rows());
  if (nv == 0 || m.F.rows() == 0) gdsr::fail("sim/cloth_solver", "garment '" + g.name + "' is empty");
  if (m.FUV.rows() != m.F.rows()) gdsr::fail("sim/cloth_solver", "garment F and FUV differ in face count");
  if (p.substeps < 1 || p.iterations < 1 || p.contact_every < 1 || p.stretch_passes < 1)
    gdsr::fail("sim/cloth_solver", "substeps, iterations, stretch_passes and contact_every must be >= 1");
  if (!(p.substep_travel >= 0) || !std::isfinite(p.substep_travel))
    gdsr::fail("sim/cloth_solver", "substep_travel must be finite and >= 0");
  if (p.substep_travel > 0 && p.max_substeps < p.substeps)
    gdsr::fail("sim/cloth_solver", "max_substeps must be >= substeps");
  if (!(p.contact_travel >= 0) || !std::isfinite(p.contact_travel))
    gdsr::fail("sim/cloth_solver", "contact_travel must be finite and >= 0");
  if (!(p.pin_yield_rate >= 0) || !std::isfinite(p.pin_yield_rate))
    gdsr::fail("sim/cloth_solver", "pin_yield_rate must be finite and >= 0");
  if (!(p.density > 0) || !(p.stretch_stiffness > 0) || !(p.bend_stiffness > 0))
    gdsr::fail("sim/cloth_solver", "density and stiffnesses must be positive");
  if (!(p.settle_rest_blend >= 0 && p.settle_rest_blend <= 1))
    gdsr::fail("sim/cloth_solver", "settle_rest_blend must be in [0, 1]");
  if (!(p.compression_ratio > 0 && p.compression_ratio <= 1))
    gdsr::fail("sim/cloth_solver", "compression_ratio must be in (0, 1]");
  if (!(p.compression_pd_ref > 0)) gdsr::fail("sim/cloth_solver", "compression_pd_ref must be positive");
  if (!(p.compression_pd_exponent >= 0 && p.compression_pd_exponent <= 4))
    gdsr::fail("sim/cloth_solver", "compression_pd_exponent must be in [0, 4]");
  if (!(p.contact_release_stretch > 1)) gdsr::fail("sim/cloth_solver", "contact_release_stretch must be > 1");
  if (!(p.dressed_radius >= 0)) gdsr::fail("sim/cloth_solver", "dressed_radius must be >= 0");
  if (!(p.max_push_step > 0)) gdsr::fail("sim/cloth_solver", "max_push_step must be positive");
  if (g.particle_distance > 0)
    p_.compression_ratio = std::min(
        1.0, p.compression_ratio * std::pow(p.compression_pd_ref / g.particle_distance, p.compression_pd_exponent));
  if (body_F.rows() > 0 && body_F.maxCoeff() >= body_V0.rows())
    gdsr::fail("sim/cloth_solver", "body faces index missing vertices");
  if (!m.V.allFinite()) gdsr::fail("sim/cloth_solver", "garment rest positions are not finite");
  if (!layer_.empty() && static_cast<int>(layer_.size()) != nv)
    gdsr::fail("sim/cloth_solver", "garment layer size differs from vertex count");

  x_ = m.V;
  v_ = Points3::Zero(nv, 3);
  xprev_ = x_;
  mass_.assign(nv, 0.0);
  for (int f = 0; f < m.F.rows(); ++f) {
    const double a = uv_area(m, f);
    for (int k = 0; k < 3; ++k) mass_[m.F(f, k)] += p.density * a / 3;
  }
  winv_.resize(nv);
  for (int v = 0; v < nv; ++v) winv_[v] = mass_[v] > 0 ? 1.0 / mass_[v] : 0.0;

  // Edges: rest length from the pattern (mean over the UV copies), area share for stiffness.
  struct EdgeAcc {
    double len = 0, area = 0;
    int n = 0;
    std::vector<std::pair<int, int>> faces;
  };
  std::map<std::pair<int, int>, EdgeAcc> emap;
  for (int f = 0; f < m.F.rows(); ++f) {
    const double a = uv_area(m, f);
    for (int k = 0; k < 3; ++k) {
      const int i = m.F(f, k), j = m.F(f, (k + 1) % 3);
      auto& e = emap[{std::min(i, j), std::max(i, j)}];
      e.len += (m.UV.row(m.FUV(f, k)) - m.UV.row(m.FUV(f, (k + 1) % 3))).norm();
      e.area += a / 3;
      ++e.n;
      e.faces.push_back({f, k});
    }
  }
  for (const auto& [key, e] : emap) {
    const double rest = e.len / e.n;
    if (!(rest > 1e-9)) gdsr::fail("sim/cloth_solver", "garment has a zero-length edge in UV");
    edges_.push_back({key.first, key.second, rest, rest * rest / (p.stretch_stiffness * e.area)});
    if (e.faces.size() != 2) continue;
    // Isometric bending stencil: edge (x0, x1), opposite x2 (face 0) and x3 (face 1).
    const int f0 = e.faces[0].first, k0 = e.faces[0].second;
    const int f1 = e.faces[1].first;
    const int x0 = m.F(f0, k0), x1 = m.F(f0, (k0 + 1) % 3), x2 = m.F(f0, (k0 + 2) % 3);
    int k1 = 0;
    while (m.F(f1, k1) == x0 || m.F(f1, k1) == x1) ++k1;
    const int x3 = m.F(f1, k1);
    auto uvof = [&](int f, int vert) {
      for (int k = 0; k < 3; ++k)
        if (m.F(f, k) == vert) return Vec2(m.UV.row(m.FUV(f, k)));
      return Vec2(0, 0);
    };
    const Vec2 a0 = uvof(f0, x0), a1 = uvof(f0, x1), a2 = uvof(f0, x2);
    const Vec2 b0 = uvof(f1, x0), b1 = uvof(f1, x1), b3 = uvof(f1, x3);
    const double c01 = cot(a1 - a0, a2 - a0), c02 = cot(b1 - b0, b3 - b0);
    const double c03 = cot(a0 - a1, a2 - a1), c04 = cot(b0 - b1, b3 - b1);
    // Energy B |K x|^2 / (2 A): for a cylinder of curvature k it sums to B k^2 / 2 per area
    // (the plate bending energy of the modulus B), checked in tests/sim/test_cantilever.cpp.
    const double A = uv_area(m, f0) + uv_area(m, f1);
    Bend b{{x0, x1, x2, x3}, {c03 + c04, c01 + c02, -c01 - c03, -c02 - c04}, A / p.bend_stiffness};
    bends_.push_back(b);
  }

  std::vector<std::array<int, 2>> edge_ends_ij(edges_.size());
  for (size_t e = 0; e < edges_.size(); ++e) edge_ends_ij[e] = {edges_[e].i, edges_[e].j};
  vertex_edges_ = gdsr::vertex_edges(edge_ends_ij, static_cast<int>(m.V.rows()));
  std::vector<GaussSeidelSchedule::Item> edge_ends(edges_.size());
  for (size_t e = 0; e < edges_.size(); ++e) edge_ends[e] = {edges_[e].i, edges_[e].j, -1, -1};
  edge_schedule_.plan(edge_ends, nv);

  // Body grid for the rest pose; initial push-out; pins.
  const double cell = std::max(0.05, p.contact_radius + p.thickness);
  if (body_F.rows() > 0) {
    grid_.build(bodyF_, body_V0, body_V0, cell);
    for (int v = 0; v < nv; ++v) {
      const SurfaceHit hit = grid_.closest(x_.row(v).transpose(), body_V0, p.thickness + p.contact_radius);
      if (hit.face >= 0 && hit.signed_distance < p.thickness)
        x_.row(v) = (hit.point + hit.normal * p.thickness).transpose();
    }
    // Where each vertex was dressed: its closest body point in the first pose (within 0.3 m).
    if (!(p.pinch_separation > 0)) gdsr::fail("sim/cloth_solver", "pinch_separation must be positive");
    body_rest_ = body_V0;
    home_ = Points3::Constant(nv, 3, std::numeric_limits<double>::quiet_NaN());
    SurfaceGrid wide;
    wide.build(bodyF_, body_V0, body_V0, 0.15);
    for (int v = 0; v < nv; ++v) {
      const SurfaceHit hit = wide.closest(x_.row(v).transpose(), body_V0, 0.3);
      if (hit.face >= 0) home_.row(v) = hit.point.transpose();
    }
    under_garment_ = points_near(body_V0, home_, p.dressed_radius);
  }
  if (!g.pinned.empty() && body_F.rows() == 0) {  // no body: pinned vertices are fixed in space
    for (int v : g.pinned) {
      if (v < 0 || v >= nv) gdsr::fail("sim/cloth_solver", "pinned vertex out of range");
      winv_[v] = 0;
    }
  } else if (!g.pinned.empty()) {
    Points3 placed(g.pinned.size(), 3);
    for (size_t k = 0; k < g.pinned.size(); ++k) {
      const int v = g.pinned[k];
      if (v < 0 || v >= nv) gdsr::fail("sim/cloth_solver", "pinned vertex out of range");
      placed.row(static_cast<Eigen::Index>(k)) = m.V.row(v);
      winv_[v] = 0;
    }
    pins_ = PinBinding(g.pinned, placed, F_, bodyF_, body_V0);
    // A layered garment's pins stay rigid (SimParams::pin_yield_rate says why).
    const bool layered = !layer_.empty() && *std::max_element(layer_.begin(), layer_.end()) > 0;
    if (p.pin_yield_rate > 0 && !layered) {
      pin_of_.assign(nv, -1);
      pin_offset_ = Points3::Zero(pins_.size(), 3);
      pin_room_.assign(pins_.size(), 0.0);
      pin_inward_ = Points3::Zero(pins_.size(), 3);
      for (int k = 0; k < pins_.size(); ++k) {
        const int v = pins_.vertex(k);
        pin_of_[v] = k;
        if (!home_.row(v).allFinite()) continue;
        const Vec3 in = (home_.row(v) - x_.row(v)).transpose();
        pin_room_[k] = std::max(0.0, in.norm() - p.thickness);
        if (pin_room_[k] > 0) pin_inward_.row(k) = in.normalized().transpose();
      }
    }
    place_pins(body_V0, 0);
  }
  if (p.implicit_bending && !bends_.empty()) {
    std::vector<BendStencil> stencils;
    stencils.reserve(bends_.size());
    for (const Bend& b : bends_)
      stencils.push_back({{b.v[0], b.v[1], b.v[2], b.v[3]}, {b.K[0], b.K[1], b.K[2], b.K[3]}, 1.0 / b.compliance});
    std::vector<char> fixed(nv);
    for (int v = 0; v < nv; ++v) fixed[v] = winv_[v] == 0;
    implicit_bending_ = std::make_unique<ImplicitBending>(nv, stencils, mass_, fixed, p.bending_jacobi_max_ratio);
  }
  // Cloth that hangs from a pin: connected to one through the mesh (see overstretched_at).
  anchored_.assign(nv, 0);
  lost_in_ = Points3::Constant(nv, 3, std::numeric_limits<double>::quiet_NaN());
  std::vector<int> reached(g.pinned.begin(), g.pinned.end());
  for (int v : reached) anchored_[v] = 1;
  for (size_t k = 0; k < reached.size(); ++k) {
    const int v = reached[k];
    for (int j = vertex_edges_.offsets[v]; j < vertex_edges_.offsets[v + 1]; ++j) {
      const Edge& e = edges_[vertex_edges_.items[j]];
      const int u = e.i == v ? e.j : e.i;
      if (!anchored_[u]) anchored_[u] = 1, reached.push_back(u);
    }
  }
  if (!g.pinned.empty() && p.tethers) {
    if (!(p.tether_stretch >= 0)) gdsr::fail("sim/cloth_solver", "tether_stretch must be >= 0");
    tethers_ = make_tethers(m, g.pinned);
  }
  for (const Edge& e : edges_) {
    edge_rest_pattern_.push_back(e.rest);
    edge_rest_placed_.push_back((m.V.row(e.i) - m.V.row(e.j)).norm());
  }
  for (const Tether& t : tethers_) {
    tether_rest_pattern_.push_back(t.rest);
    tether_rest_placed_.push_back(std::max(t.rest, (m.V.row(t.v) - m.V.row(t.pin)).norm()));
  }
  body_cell_ = cell;
  xprev_ = x_;
  if (p.self_collision) {
    if (!(p.self_thickness > 0) || p.self_detect_every < 1 || !(p.self_slack > 0) || p.self_passes < 1 ||
        !(p.self_thickness_per_pd >= 0) || !(p.self_slack_per_pd > 0) || !(p.self_crossed_push >= 1))
      gdsr::fail("sim/cloth_solver",
                 "self_thickness, self_slack and self_slack_per_pd must be positive, self_thickness_per_pd >= 0, "
                 "self_crossed_push, self_detect_every and self_passes >= 1");
    p_.self_thickness = std::max(p.self_thickness, p.self_thickness_per_pd * g.particle_distance);
    if (g.particle_distance > 0) p_.self_slack = std::min(p.self_slack, p.self_slack_per_pd * g.particle_distance);
    const double longer = std::round(p.self_detect_every * (p.self_slack / p_.self_slack));
    p_.self_detect_every = static_cast<int>(std::min(longer, 1000.0));
    self_ = std::make_unique<SelfCollision>(F_, nv);
    self_->set_refuse_crossing_pushes(p_.self_refuse_crossing_push);
    if (p_.self_refuse_crossing_push) {  // otherwise body_moved_ stays empty, and nothing keeps it
      body_moved_.assign(nv, 0);
      self_->set_body_moved(&body_moved_);
    }
    motion_ = Points3::Zero(nv, 3);
  }
}

void ClothSolver::set_positions(const Points3& X) {
  if (X.rows() != x_.rows() || X.cols() != 3 || !X.allFinite())
    gdsr::fail("sim/cloth_solver", "start positions must be finite, " + std::to_string(x_.rows()) + " x 3");
  x_ = X;
  xprev_ = X;
  v_.setZero();
  since_detect_ = 1 << 30;
  tangle_test_due_ = true;
}

void ClothSolver::set_rest_blend(double a) {
  if (!(a >= 0 && a <= 1)) gdsr::fail("sim/cloth_solver", "rest blend must be in [0, 1]");
  for (size_t c = 0; c < edges_.size(); ++c)
    edges_[c].rest = edge_rest_placed_[c] + a * (edge_rest_pattern_[c] - edge_rest_placed_[c]);
  for (size_t c = 0; c < tethers_.size(); ++c)
    tethers_[c].rest = tether_rest_placed_[c] + a * (tether_rest_pattern_[c] - tether_rest_placed_[c]);
}

void ClothSolver::place_pins(const Points3& body, double h) {
  pins_.place(body, x_, pin_of_.empty() ? nullptr : &band_rotation_);
  if (pin_of_.empty()) return;
  const double decay = std::exp(-p_.pin_yield_rate * h);
  for (int k = 0; k < pins_.size(); ++k) {
    if (pin_offset_.row(k).isZero(0)) continue;
    pin_offset_.row(k) *= decay;
    x_.row(pins_.vertex(k)) += (band_rotation_[pins_.band(k)] * pin_offset_.row(k).transpose()).transpose();
  }
}

bool ClothSolver::under_garment(int body_face) const {
  for (int k = 0; k < 3; ++k)
    if (under_garment_[bodyF_(body_face, k)]) return true;
  return false;
}

bool ClothSolver::in_part(const Contact& c, const Vec3& part) const {
  return (bary_point(body_rest_, bodyF_, c.face, c.bary) - part).squaredNorm() <=
         p_.pinch_separation * p_.pinch_separation;
}

bool ClothSolver::part_contacts(int u, const Vec3& part, bool drop, std::vector<std::array<Contact, 2>>& found,
                                std::vector<signed char>& count) const {
  int kept = 0;
  bool any = false;
  for (int k = 0; k < count[u]; ++k) {
    Contact c = found[u][k];
    const bool in_part = this->in_part(c, part);
    any = any || in_part;
    if (in_part && drop) continue;
    c.passing = c.passing || in_part;
    found[u][kept++] = c;
  }
  count[u] = static_cast<signed char>(kept);
  return any;
}

void ClothSolver::pass_limbs_through(const std::vector<Contact>& pierced, std::vector<std::array<Contact, 2>>& found,
                                     std::vector<signed char>& count) {
  const int nv = static_cast<int>(x_.rows());
  if (remembered_ == 0 && std::none_of(pierced.begin(), pierced.end(), [](const Contact& c) { return c.v >= 0; }))
    return;  // nothing lost in a part: the common case, on every refresh
  // Per vertex: the part (a point of it in the first pose) whose contacts v and its edge
  // neighbours drop (lost in it now) or hold as passing (lost in it before, still within reach).
  Points3 lost = Points3::Constant(nv, 3, std::numeric_limits<double>::quiet_NaN());
  std::vector<char> deep(nv, 0);
  for (int v = 0; v < nv; ++v) {
    if (pierced[v].v >= 0) {
      lost.row(v) = bary_point(body_rest_, bodyF_, pierced[v].face, pierced[v].bary).transpose();
      deep[v] = 1;
      continue;
    }
    if (!p_.limbs_pass_until_clear || !lost_in_.row(v).allFinite()) continue;
    for (int k = 0; k < count[v]; ++k)
      if (in_part(found[v][k], lost_in_.row(v).transpose())) lost.row(v) = lost_in_.row(v);
  }
  Points3 next = lost;  // the memory for the next refresh: what is lost now, and the neighbours it reaches
  for (int v = 0; v < nv; ++v) {
    if (!lost.row(v).allFinite()) continue;
    const Vec3 part = lost.row(v).transpose();
    part_contacts(v, part, deep[v], found, count);
    for (int k = vertex_edges_.offsets[v]; k < vertex_edges_.offsets[v + 1]; ++k) {
      const Edge& e = edges_[vertex_edges_.items[k]];
      const int u = e.i == v ? e.j : e.i;
      if (part_contacts(u, part, deep[v], found, count) && anchored_[u] && !next.row(u).allFinite())
        next.row(u) = part.transpose();
    }
  }
  if (!p_.limbs_pass_until_clear) return;
  lost_in_ = std::move(next);
  remembered_ = 0;
  for (int v = 0; v < nv; ++v) remembered_ += lost_in_.row(v).allFinite();
}

void ClothSolver::refresh_contacts(const Points3& body_now, double h) {
  contacts_.clear();
  const int nv = static_cast<int>(x_.rows());
  if (bodyF_.rows() > 0) {
    const double r = p_.thickness + p_.contact_radius;
    const double until_next = p_.contact_travel * h * p_.contact_every;  // seconds of travel covered
    const double sep2 = p_.pinch_separation * p_.pinch_separation;
    // Up to two contacts per vertex, found in parallel (each vertex fills its own slots),
    // then gathered in vertex order, so the result does not depend on the thread count.
    std::vector<std::array<Contact, 2>> found(nv);
    std::vector<signed char> count(nv, 0);
    std::vector<Contact> pierced(nv, Contact{-1, -1, Vec3::Zero()});  // per vertex: the part it is lost in
    auto add = [&](int v, const SurfaceHit& hit) {
      // Deeper than max_push: the vertex went through a thin part; pushing it out would tear
      // the cloth, so leave it.
      if (hit.signed_distance > -p_.max_push) found[v][count[v]++] = {v, hit.face, hit.bary};
    };
    auto foreign_to = [&](const Vec3& home) {  // faces of parts other than the one around `home`
      return [this, home, sep2](int f) {
        for (int k = 0; k < 3; ++k)
          if ((body_rest_.row(bodyF_(f, k)).transpose() - home).squaredNorm() <= sep2) return false;
        return true;
      };
    };
#pragma omp parallel
    {
      SurfaceCandidates near;  // the faces within r of the vertex: its two queries below share them
#pragma omp for schedule(dynamic, 256)
      for (int v = 0; v < nv; ++v) {
        if (winv_[v] == 0) {  // a pin: only a part it was not dressed on may press it (pin_yield_rate)
          if (pin_of_.empty() || pin_of_[v] < 0 || !(pin_room_[pin_of_[v]] > 0)) continue;
          const SurfaceHit b = grid_.closest(x_.row(v).transpose(), body_now, r, foreign_to(home_.row(v).transpose()));
          if (b.face >= 0) add(v, b);
          continue;
        }
        const Vec3 x = x_.row(v).transpose();
        // Nothing within the fixed radius: farther, a surface the vertex approaches fast enough to be
        // within that radius by the next refresh (the body's own motion is left to the radius).
        grid_.candidates(x, body_now, r, near);
        SurfaceHit a = grid_.closest(near, body_now);
        const double travel = until_next * v_.row(v).norm();
        if (a.face < 0 && travel > 0) {
          a = grid_.closest(x, body_now, r + travel);
          if (a.face >= 0 && a.signed_distance + until_next * v_.row(v).dot(a.normal) > r) continue;
        }
        if (a.face < 0) continue;
        const Vec3 ra = bary_point(body_rest_, bodyF_, a.face, a.bary);
        const bool dressed = home_.row(v).allFinite();
        // Lost inside a part it was not dressed on and no cloth was dressed on (limbs_pass_through,
        // dressed_radius): a hand, not the leg a trouser leg hangs on, nor the thigh that a kneel
        // closes onto the calf with the trouser in the crook.
        if (a.signed_distance <= -p_.max_push && anchored_[v] &&
            (!dressed || (ra - home_.row(v).transpose()).squaredNorm() > sep2) && !under_garment(a.face))
          pierced[v] = {v, a.face, a.bary};
        // A second body part within reach (far from the first one in the first pose): the cloth
        // may be pinched between them (a hand pressing a skirt onto the hip). Both contacts
        // apply; the part the vertex was dressed on comes last, so it wins when they conflict.
        if (!dressed) {  // dressed nowhere near the body: nothing to prefer
          add(v, a);
          continue;
        }
        const SurfaceHit b = grid_.closest(near, body_now, foreign_to(ra));
        if (b.face < 0) {
          add(v, a);
          continue;
        }
        const Vec3 home = home_.row(v).transpose();
        const Vec3 rb = bary_point(body_rest_, bodyF_, b.face, b.bary);
        const bool a_home = (ra - home).squaredNorm() <= (rb - home).squaredNorm();
        add(v, a_home ? b : a);
        add(v, a_home ? a : b);
      }
    }
    if (p_.limbs_pass_through) pass_limbs_through(pierced, found, count);
    for (int v = 0; v < nv; ++v)
      for (int k = 0; k < count[v]; ++k) contacts_.push_back(found[v][k]);
  }
  layer_pairs_.clear();
  if (layer_.empty()) return;
  int nlayers = 1 + *std::max_element(layer_.begin(), layer_.end());
  if (nlayers < 2) return;
  // Vertex normals (area weighted) of the current cloth.
  Points3 N = Points3::Zero(nv, 3);
  for (int f = 0; f < F_.rows(); ++f) {
    const Vec3 a = x_.row(F_(f, 0)), b = x_.row(F_(f, 1)), c = x_.row(F_(f, 2));
    const Vec3 n = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) N.row(F_(f, k)) += n.transpose();
  }
  const double r = 2 * p_.layer_gap + 0.02;
  std::unordered_map<long long, std::vector<int>> cells;
  auto key = [](long long i, long long j, long long k) {
    return ((i + (1 << 20)) * (1LL << 21) + (j + (1 << 20))) * (1LL << 21) + (k + (1 << 20));
  };
  for (int v = 0; v < nv; ++v) {
    const Eigen::Vector3i c = (x_.row(v).transpose() / r).array().floor().cast<int>();
    cells[key(c.x(), c.y(), c.z())].push_back(v);
  }
  for (int v = 0; v < nv; ++v) {
    if (layer_[v] == 0) continue;
    const Vec3 x = x_.row(v).transpose();
    const Eigen::Vector3i c = (x / r).array().floor().cast<int>();
    int best = -1;
    double bd = r * r;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) {
          auto it = cells.find(key(c.x() + i, c.y() + j, c.z() + k));
          if (it == cells.end()) continue;
          for (int u : it->second) {
            if (layer_[u] != layer_[v] - 1) continue;
            const double d = (x_.row(u).transpose() - x).squaredNorm();
            if (d < bd || (d == bd && u < best)) {
              bd = d;
              best = u;
            }
          }
        }
    // Only layers lying flat on each other are paired (normals within 60 degrees): across a
    // fold the nearest inner vertex may face any way, and pushing along its normal drove the
    // outer layer through the inner one (revision 9: the 10 mm layered dress on CMU 01_01
    // tangled at the hip and blew up; without self-contact, the 40 mm layered skirt at rest
    // with compression_pd_exponent 1 wound its overskirt inside the underskirt). With
    // self-contact, also only an outer vertex on the inner one's outer side: self-contact
    // guards the rest. Without it, pairing is the only way back out, so one found inside is
    // paired (and pushed out).
    if (best >= 0 && (N.row(v).dot(N.row(best)) < 0.5 * N.row(v).norm() * N.row(best).norm() ||
                      (self_ && (x_.row(v) - x_.row(best)).dot(N.row(best)) < 0)))
      continue;
    if (best >= 0 && N.row(best).norm() > 0) layer_pairs_.push_back({v, best, N.row(best).normalized().transpose()});
  }
}

void ClothSolver::detect_self_contacts(double h) {
  // On the current (intersection-free) state, covering the motion of the next
  // self_detect_every substeps; sooner when a vertex left its slack (track_self_slack).
  // The tangle test (edges crossing faces) runs at the first detection of each frame, and
  // again after a substep that ended pushing pairs back across (SimParams::self_tangle_retest):
  // it was a fifth of a detection's time, and an intersection that slipped through stays
  // guarded for at most one frame before it is freed to untangle.
  //
  // The interval adapts to the cloth's speed: each vertex's box covers its motion over the
  // interval, so fast cloth (a garment dragged by a fast limb, or still far from rest) would
  // meet hundreds of faces per box: a pants simulation on CMU 01_01 had 1.6 million candidate
  // pairs per detection and grew to 16 GB. The interval halves until the 99th percentile of
  // the motion over it, less the cloth's mean motion (the boxes are taken in a frame moving
  // with it, so cloth carried along by the body costs nothing), is within twice the boxes'
  // padding (at the padding itself, a skirt on 01_01 detected so often that it ran 9% slower).
  // Any interval is safe: every vertex is still tracked against its slack. On 1 s of the
  // t-shirt on CMU salsa 60_02 (HR, 13,428 vertices), the motion itself detected 1,577 times,
  // the motion less the mean 1,328 (HR 1.95 -> 1.58 CPU s per frame). A lower percentile
  // detects less often again (95th: 1,093, 1.45 s), but on 4 s of that clip one of two runs
  // (friction nudged by 1e-5) had the HR cloth through itself in its last 15 frames (89.0%
  // clean; 100% in the other, and in both at the 99th).
  if (!self_) return;
  if (since_detect_ < detect_interval_ && (left_slack_.empty() || redetect_self_contacts(h))) return;
  const int nv = static_cast<int>(x_.rows());
  std::vector<double> speed(nv);
  // The guide's pull (track_guide) moves the cloth too: left out of the motion, a pair it pushed
  // across looked like an intersection that had slipped through, and was freed.
  const bool pulled = pull_step_.rows() == nv;
  Points3 vel = v_;
  if (pulled) vel += pull_step_ / h;
  const Eigen::RowVector3d mean_vel = vel.colwise().mean();
  for (int v = 0; v < nv; ++v) speed[v] = (vel.row(v) - mean_vel).norm();
  const int q = std::min(nv - 1, nv * 99 / 100);
  std::nth_element(speed.begin(), speed.begin() + q, speed.end());
  const double pad = 0.5 * p_.self_thickness + p_.self_slack;
  detect_interval_ = p_.self_detect_every;
  while (detect_interval_ > 1 && speed[q] * detect_interval_ * h > 2 * pad) detect_interval_ = (detect_interval_ + 1) / 2;
  for (int v = 0; v < nv; ++v) motion_.row(v) = predicted_motion(v, detect_interval_, h);
  self_->detect(x_, motion_, p_.self_slack, p_.self_thickness, tangle_test_due_);
  tangle_test_due_ = false;
  x_detect_ = x_;
  since_detect_ = 0;
  left_slack_.clear();
  redetected_.assign(nv, 0);
}

Eigen::RowVector3d ClothSolver::predicted_motion(int v, int substeps, double h) const {
  // Free flight (a pinned vertex keeps its velocity) plus the guide's pull (track_guide; see
  // detect_self_contacts for why it counts).
  const double T = substeps * h;
  Eigen::RowVector3d m = v_.row(v) * T + (winv_[v] == 0 ? 0.0 : 0.5 * T * T) * p_.gravity.transpose();
  if (pull_step_.rows() == x_.rows()) m += substeps * pull_step_.row(v);
  return m;
}

bool ClothSolver::redetect_self_contacts(double h) {
  // Vertices left their slack mid-interval (a limb pushed them, say: on salsa 61_03 that was half
  // of all detections, most after one substep, a few vertices at a time): only they get a new
  // path, from where they are over the rest of the interval, and only their pairs are found
  // again (SelfCollision::redetect); the pairs of the rest are still good. A full detection
  // instead when it also owes the frame's tangle test, or when many vertices have moved.
  const int nv = static_cast<int>(x_.rows());
  int moved = static_cast<int>(std::count(redetected_.begin(), redetected_.end(), 1));
  for (int v : left_slack_) moved += !redetected_[v];
  if (!p_.self_redetect || tangle_test_due_ || moved > nv / 4) return false;
  const double a = static_cast<double>(since_detect_) / detect_interval_;  // of the interval, gone
  const int left = detect_interval_ - since_detect_;                       // substeps to go
  for (int v : left_slack_) {
    motion_.row(v) = predicted_motion(v, left, h) / (1 - a);
    x_detect_.row(v) = x_.row(v) - a * motion_.row(v);
    redetected_[v] = 1;
  }
  left_slack_.clear();
  const Points3 start = x_detect_ + a * motion_, rest = (1 - a) * motion_;
  self_->redetect(x_, start, rest, redetected_, a, p_.self_slack, p_.self_thickness);
  return true;
}

void ClothSolver::predict(double h, double decay) {
  xprev_ = x_;
  const int nv = static_cast<int>(x_.rows());
  for (int v = 0; v < nv; ++v) {
    if (winv_[v] == 0) continue;
    Vec3 vel = (v_.row(v).transpose() + h * p_.gravity) * decay;
    const double sp = vel.norm();
    if (sp > p_.max_speed) vel *= p_.max_speed / sp;
    v_.row(v) = vel.transpose();
    x_.row(v) += h * vel.transpose();
  }
}

void ClothSolver::prepare_stretch_pass(double h2) {
  // Once per substep, before the passes, each edge's compliance factor from its strain: 1 when
  // stretched, 1 / compression_ratio beyond 0.1% compression, a smoothstep between (a jump at
  // zero strain, or a switch between passes with lambda from the other regime, makes edges
  // near their rest length chatter). Stored with what the passes read of the edge, by its slot
  // in edge_schedule_.
  const double eps0 = 1e-3;
  pass_edges_.resize(edges_.size());
  const int ne = static_cast<int>(edges_.size());
#pragma omp parallel for schedule(static) num_threads(2) if (ne > 4096 && omp_get_max_threads() > 1)
  for (int c = 0; c < ne; ++c) {
    const Edge& e = edges_[c];
    const double strain = (x_.row(e.i) - x_.row(e.j)).norm() / e.rest - 1;
    const double t = std::clamp(1 + strain / eps0, 0.0, 1.0), s = t * t * (3 - 2 * t);
    const double scale = 1 / (p_.compression_ratio + (1 - p_.compression_ratio) * s);
    pass_edges_[edge_schedule_.slot(c)] = {e.i, e.j, e.rest, scale * e.compliance / h2};
  }
}

void ClothSolver::solve_edges(std::vector<double>& lambda) {
  // Each edge sees every earlier edge's moves, as in a pass in edge order; on two threads for a
  // fine mesh with the same result (GaussSeidelSchedule). lambda: by slot.
  auto solve = [&](int, int slot) {
    const PassEdge& e = pass_edges_[slot];
    const double wi = winv_[e.i], wj = winv_[e.j];
    if (wi + wj == 0) return;
    Vec3 d = x_.row(e.i) - x_.row(e.j);
    const double len = d.norm();
    if (len < 1e-12) return;
    d /= len;
    const double dl = (-(len - e.rest) - e.at * lambda[slot]) / (wi + wj + e.at);
    lambda[slot] += dl;
    x_.row(e.i) += (wi * dl) * d.transpose();
    x_.row(e.j) -= (wj * dl) * d.transpose();
  };
  // Below ~10k edges the threads' start-up and waits cost more than they save.
  constexpr int kScheduledEdges = 8192;
  if (edge_schedule_.size() >= kScheduledEdges)
    edge_schedule_.run(solve);
  else
    for (int c = 0; c < static_cast<int>(edges_.size()); ++c) solve(c, edge_schedule_.slot(c));
}

void ClothSolver::solve_bends(std::vector<double>& lambda_b, double h2) {
  for (size_t c = 0; c < bends_.size(); ++c) {
    const Bend& b = bends_[c];
    Vec3 q = Vec3::Zero();
    double wsum = 0;
    for (int k = 0; k < 4; ++k) {
      q += b.K[k] * x_.row(b.v[k]).transpose();
      wsum += winv_[b.v[k]] * b.K[k] * b.K[k];
    }
    const double C = q.norm();
    if (C < 1e-12 || wsum == 0) continue;
    const Vec3 dir = q / C;
    const double at = b.compliance / h2;
    const double dl = (-C - at * lambda_b[c]) / (wsum + at);
    lambda_b[c] += dl;
    for (int k = 0; k < 4; ++k) x_.row(b.v[k]) += (winv_[b.v[k]] * b.K[k] * dl) * dir.transpose();
  }
}

void ClothSolver::solve_layers() {
  for (const auto& lp : layer_pairs_) {
    const double wo = winv_[lp.outer], wi = winv_[lp.inner];
    if (wo + wi == 0) continue;
    const double C = (x_.row(lp.outer) - x_.row(lp.inner)).dot(lp.normal.transpose()) - p_.layer_gap;
    if (C >= 0) continue;
    if (self_ && C < -p_.layer_gap) continue;  // crossed since pairing: left to self-contact's untangling
    x_.row(lp.outer) -= (wo * C / (wo + wi)) * lp.normal.transpose();
    x_.row(lp.inner) += (wi * C / (wo + wi)) * lp.normal.transpose();
  }
}

bool ClothSolver::overstretched_at(int v, const Vec3& x) const {
  if (!anchored_[v]) return false;
  const double limit = p_.contact_release_stretch;
  for (int k = vertex_edges_.offsets[v]; k < vertex_edges_.offsets[v + 1]; ++k) {
    const Edge& e = edges_[vertex_edges_.items[k]];
    const Vec3 other = x_.row(e.i == v ? e.j : e.i).transpose();
    const double now = (x - other).norm(), before = (x_.row(v).transpose() - other).norm();
    if (now > limit * e.rest && now > before) return true;
  }
  return false;
}

void ClothSolver::solve_body_contacts(const Points3& body_prev, const Points3& body_now) {
  // Cloth that hangs from no pin is pushed out gradually (SimParams::max_push_step). A vertex's
  // contacts are consecutive, the part that wins a pinch last: it may undo the push of the one
  // before.
  int pushed_v = -1;
  double pushed = 0;
  std::fill(body_moved_.begin(), body_moved_.end(), 0);
  auto depth = [&](const Contact& c) {
    return (x_.row(c.v).transpose() - bary_point(body_now, bodyF_, c.face, c.bary))
               .dot(face_normal(body_now, bodyF_, c.face)) -
           p_.thickness;
  };
  for (size_t k = 0; k < contacts_.size(); ++k) {
    const Contact& c = contacts_[k];
    if (c.v != pushed_v) pushed_v = c.v, pushed = 0;
    const double C = depth(c);
    if (C >= 0) continue;
    // Cloth without a pin inside two parts at once (an arm pressed into the chest): each push
    // would move it onto one part's surface inside the other, and sleeve and shirt, pushed onto
    // their own parts, would swap sides. Held where it is, self-contact keeps the layers in order.
    // (A vertex has at most two contacts, next to each other.)
    if (p_.hold_unpinned_pinches && !anchored_[c.v]) {
      const size_t other = k + 1 < contacts_.size() && contacts_[k + 1].v == c.v ? k + 1
                           : k > 0 && contacts_[k - 1].v == c.v                  ? k - 1
                                                                                 : k;
      if (other != k && depth(contacts_[other]) < 0) continue;
    }
    const Vec3 q = bary_point(body_now, bodyF_, c.face, c.bary);
    const Vec3 nrm = face_normal(body_now, bodyF_, c.face);
    Vec3 x = x_.row(c.v).transpose();
    if (winv_[c.v] == 0) {  // a pin pressed by a foreign part towards its home, within its room (pin_yield_rate)
      // Only towards the home (the hip under a hand): pressed along the hand's normal, the band slid
      // over the folds hanging from it and crossed them (10 mm pleated skirt on salsa 61_03).
      const int pin = pin_of_[c.v];
      const Vec3 in = pin_inward_.row(pin).transpose();
      const double along = (band_rotation_[pins_.band(pin)] * in).dot(nrm);  // depth undone per m pressed home
      if (!(along > kMinPinPress)) continue;
      const double pressed = pin_offset_.row(pin).dot(in.transpose());
      const double t = std::min(-C / along, pin_room_[pin] - pressed);
      const Vec3 moved = x + t * (band_rotation_[pins_.band(pin)] * in);
      // Also when the part went through the cloth around it (passing): pressed no farther than its
      // room, the band is not carried along.
      if (!(t > 0) || overstretched_at(c.v, moved)) continue;
      pin_offset_.row(pin) += t * in.transpose();
      x_.row(c.v) = moved.transpose();
      continue;
    }
    const Vec3 qprev = bary_point(body_prev, bodyF_, c.face, c.bary);
    if (c.passing && (q - qprev).dot(nrm) > 0) continue;  // a limb that went through it does not push it on
    const double push =
        anchored_[c.v] ? -C : std::min(-C, std::max(0.0, (q - qprev).dot(nrm)) + p_.max_push_step + pushed);
    x += push * nrm;
    pushed = push;
    if (overstretched_at(c.v, x)) continue;
    // Coulomb friction on the displacement relative to the body point this substep (none from
    // a part passing through the cloth: it would drag the cloth along).
    Vec3 rel = (x - xprev_.row(c.v).transpose()) - (q - qprev);
    rel -= rel.dot(nrm) * nrm;
    const double rl = rel.norm();
    const double lim = p_.friction * (-C);
    if (rl > 0 && !c.passing) x -= (rl <= lim ? 1.0 : lim / rl) * rel;
    x_.row(c.v) = x.transpose();
    if (!body_moved_.empty()) body_moved_[c.v] = 1;
  }
}

void ClothSolver::solve_self_contacts() {
  // After body contact: cloth folded against the body keeps its layers apart (thickness
  // margin) instead of being pressed onto one surface. A few passes: contacts share
  // vertices, and one Gauss-Seidel pass leaves them coupled.
  if (!self_) return;
  const double max_crossed_push = p_.self_crossed_push * p_.self_thickness;
  // Pins that a hand may press into the cloth (pin_yield_rate): their free partners are moved no
  // more than C over a quarter (SelfCollision::project). Pushed by C over its weight, a vertex
  // under the 10 mm pleated waistband was thrown 1.7 m in one pass.
  const double min_mass_share = pin_of_.empty() ? 0.0 : 0.25;
  for (int k = 0;
       k < p_.self_passes && self_->project(x_, winv_, p_.self_thickness, max_crossed_push, min_mass_share) > 0; ++k) {
  }
}

void ClothSolver::update_velocities(double h) {
  const int nv = static_cast<int>(x_.rows());
  for (int v = 0; v < nv; ++v) v_.row(v) = (x_.row(v) - xprev_.row(v)) / h;
}

void ClothSolver::track_self_slack() {
  // The vertices that left the slack around their predicted path: their pairs are found again
  // at the next substep (redetect_self_contacts).
  if (!self_) return;
  ++since_detect_;
  const int nv = static_cast<int>(x_.rows());
  const double a = static_cast<double>(since_detect_) / detect_interval_;
  const double s2 = p_.self_slack * p_.self_slack;
  left_slack_.clear();
  if (since_detect_ >= detect_interval_) return;  // detected anew next substep anyway
  for (int v = 0; v < nv; ++v)
    if ((x_.row(v) - x_detect_.row(v) - a * motion_.row(v)).squaredNorm() > s2) left_slack_.push_back(v);
}

void ClothSolver::set_guide(const GuideTracker* tracker, const Points3* from, const Points3* to) {
  if (tracker && (!from || !to || tracker->hr_vertices() != x_.rows() || from->rows() != tracker->lr_vertices() ||
                  to->rows() != tracker->lr_vertices()))
    gdsr::fail("sim/cloth_solver", "the guide's vertex counts do not match the garment and its LR mesh");
  tracker_ = tracker;
  guide_from_ = tracker ? from : nullptr;
  guide_to_ = tracker ? to : nullptr;
}

void ClothSolver::track_guide(double a0, double dt, double h) {
  if (!tracker_ || !(p_.track_rate > 0)) {
    pull_step_.resize(0, 3);
    return;
  }
  const Points3 g = (1 - a0) * *guide_from_ + a0 * *guide_to_;
  const Points3 gv = (*guide_to_ - *guide_from_) / dt;
  // Cloth that went through itself is left to untangling; three rings of edges are about one LR
  // particle distance (30 mm) at 10 mm.
  constexpr int kTrackFreeRings = 3;
  const double beta = 1 - std::exp(-p_.track_rate * h);
  const Points3 before = x_;
  if (!self_ || self_->num_tangled_vertices() == 0)
    tracker_->pull(g, gv, beta, winv_, x_, v_);
  else
    tracker_->pull(g, gv, beta, untangled_pull_weights(winv_, self_->tangled(), F_, kTrackFreeRings), x_, v_);
  pull_step_ = x_ - before;
}

int ClothSolver::substeps_for(double dt) const {
  const int n = p_.substeps;
  if (!(p_.substep_travel > 0) || x_.rows() == 0) return n;
  const Eigen::RowVector3d mean_v = v_.colwise().mean();
  double fastest = 0;  // m/s, relative to the mean
  for (Eigen::Index v = 0; v < v_.rows(); ++v) fastest = std::max(fastest, (v_.row(v) - mean_v).norm());
  const double wanted = std::ceil(fastest * dt / p_.substep_travel);
  if (!(wanted > n)) return n;  // NaN velocities fail after the step
  // Multiples of a quarter of `substeps`: the implicit bending solve keeps a factorisation per substep length.
  const int quantum = std::max(1, n / 4);
  return static_cast<int>(std::min<double>(p_.max_substeps, n + std::ceil((wanted - n) / quantum) * quantum));
}

void ClothSolver::step(const Points3& body_from, const Points3& body_to, double dt) {
  if (!(dt > 0)) gdsr::fail("sim/cloth_solver", "frame time must be positive");
  const bool has_body = bodyF_.rows() > 0;
  if (has_body && (body_from.rows() != body_to.rows() || body_from.rows() <= bodyF_.maxCoeff()))
    gdsr::fail("sim/cloth_solver", "body pose vertex count does not match the body faces");
  const int n = substeps_for(dt);
  num_substeps_ += n;
  const double h = dt / n;
  const double h2 = h * h;
  if (has_body) grid_.build(bodyF_, body_from, body_to, body_cell_);
  Points3 body_prev = body_from, body_now = body_from;
  const double decay = std::exp(-p_.damping * h);
  std::vector<double> lambda_e(edges_.size()), lambda_b(bends_.size());
  tangle_test_due_ = true;

  for (int s = 0; s < n; ++s) {
    // The body moves linearly from body_from to body_to over the frame.
    if (has_body) {
      body_prev = body_now;
      const double a = static_cast<double>(s + 1) / n;
      body_now = (1 - a) * body_from + a * body_to;
      if (s % p_.contact_every == 0) refresh_contacts(body_prev, h);
    } else if (s % p_.contact_every == 0) {
      refresh_contacts(body_now, h);
    }
    track_guide(static_cast<double>(s) / n, dt, h);
    detect_self_contacts(h);
    predict(h, decay);
    if (has_body) place_pins(body_now, h);
    if (implicit_bending_) implicit_bending_->solve(h, x_);
    std::fill(lambda_e.begin(), lambda_e.end(), 0.0);
    prepare_stretch_pass(h2);
    std::fill(lambda_b.begin(), lambda_b.end(), 0.0);
    if (self_ && p_.untangle_step > 0) self_->untangle(x_, winv_, p_.untangle_step * p_.self_thickness);
    for (int it = 0; it < p_.iterations; ++it) {
      for (int k = 0; k < p_.stretch_passes; ++k) {
        solve_edges(lambda_e);
        project_tethers(tethers_, p_.tether_stretch, x_);
      }
      if (!implicit_bending_) solve_bends(lambda_b, h2);
      solve_layers();
      solve_body_contacts(body_prev, body_now);
      solve_self_contacts();
    }
    // Self-contact ended the substep pushing pairs back across: maybe cloth pressed through itself
    // with its sides taken from the crossed positions (SimParams::self_tangle_retest).
    if (self_ && p_.self_tangle_retest && self_->num_crossed_pushed() > 0) tangle_test_due_ = true;
    update_velocities(h);
    track_self_slack();
  }
  if (!x_.allFinite()) gdsr::fail("sim/cloth_solver", "simulation produced non-finite positions");
}

std::vector<Points3> simulate_frames(const Garment& g, const gdsr::Faces& body_F, const std::vector<Points3>& frames,
                                     double fps, const SimParams& p, const gdsr::ProgressFn& progress,
                                     const Points3* start, const Guide* guide, double* substeps_per_frame) {
  if (frames.empty()) gdsr::fail("sim/cloth_solver", "no body frames");
  if (guide && guide->frames.size() != frames.size())
    gdsr::fail("sim/cloth_solver", "the guide has " + std::to_string(guide->frames.size()) + " frames for " +
                                       std::to_string(frames.size()) + " body frames");
  if (!(fps > 0)) gdsr::fail("sim/cloth_solver", "fps must be positive");
  for (size_t t = 0; t < frames.size(); ++t)
    if (frames[t].rows() != frames[0].rows() || !frames[t].allFinite())
      gdsr::fail("sim/cloth_solver",
                 "body frame " + std::to_string(t) + " has a different vertex count or non-finite values");
  ClothSolver solver(g, body_F, frames[0], p);
  const double dt = 1.0 / fps;
  const int total = static_cast<int>(frames.size()) + p.settle_frames;
  int done = 0;
  // Damped dynamics on the first pose: zeroing the velocity after every frame instead would let
  // the garment fall only ~0.5 g dt^2 (5 mm at 30 fps) per frame, so the clip would start in
  // the placement shape and the fall would happen during the motion, differently at each resolution.
  solver.set_damping(p.settle_damping);
  if (start) solver.set_positions(*start);
  const double blend_frames = std::max(1.0, p.settle_rest_blend * p.settle_frames);
  if (guide) solver.set_guide(&guide->tracker, &guide->frames[0], &guide->frames[0]);  // the settle follows frame 0
  for (int k = 0; k < p.settle_frames; ++k) {
    solver.set_rest_blend(start ? 1.0 : std::min(1.0, (k + 1) / blend_frames));
    solver.step(frames[0], frames[0], dt);
    if (progress) progress(++done, total);
  }
  solver.set_rest_blend(1);
  solver.set_damping(p.damping);
  solver.zero_velocities();
  std::vector<Points3> out;
  out.reserve(frames.size());
  out.push_back(solver.positions());
  if (progress) progress(++done, total);
  for (size_t t = 1; t < frames.size(); ++t) {
    try {
      if (guide) solver.set_guide(&guide->tracker, &guide->frames[t - 1], &guide->frames[t]);
      solver.step(frames[t - 1], frames[t], dt);
    } catch (const std::runtime_error& e) {
      gdsr::fail("sim/cloth_solver", "frame " + std::to_string(t) + ": " + e.what());
    }
    out.push_back(solver.positions());
    if (progress) progress(++done, total);
  }
  const int steps = total - 1;  // frame 0 is the settle's end
  if (substeps_per_frame) *substeps_per_frame = steps > 0 ? static_cast<double>(solver.num_substeps()) / steps : 0;
  return out;
}

}  // namespace sim

// A human-like body around a bare skeleton: bones are classified by name (CMU/Mixamo
// style names), limbs become tapered capsules, the torso a stack of elliptic capsules
// through landmarks (hip joints, shoulder joints, neck), the head an ellipsoid. Their
// smooth union is meshed once at the rest pose (marching tetrahedra + CGAL isotropic
// remeshing: closed, manifold, deterministic); vertices are skinned to the bones owning the nearest primitives.
#include "gdsr/body_shape.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <stdexcept>
#include <unordered_map>

namespace gdsr::detail {
namespace {

enum class Part { Skip, Torso, Neck, Head, Clavicle, UpperArm, ForeArm, Hand, Thigh, Shin, Foot, Toe, Other };

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}
bool has(const std::string& s, const char* k) { return s.find(k) != std::string::npos; }

Part classify(const std::string& name) {
  const std::string s = lower(name);
  if (has(s, "finger") || has(s, "thumb") || has(s, "index") || has(s, "pinky") || has(s, "ring") ||
      has(s, "middle") || has(s, "endsite") || has(s, "_end"))
    return Part::Skip;
  if (has(s, "hipjoint")) return Part::Skip;  // root -> hip joint: inside the pelvis
  if (has(s, "hand") || has(s, "wrist")) return Part::Hand;
  if (has(s, "forearm") || has(s, "lowerarm") || has(s, "elbow")) return Part::ForeArm;
  if (has(s, "shoulder") || has(s, "clavicle") || has(s, "collar")) return Part::Clavicle;
  if (has(s, "arm")) return Part::UpperArm;
  if (has(s, "upleg") || has(s, "thigh") || has(s, "upperleg")) return Part::Thigh;
  if (has(s, "toe")) return Part::Toe;
  if (has(s, "foot") || has(s, "ankle")) return Part::Foot;
  if (has(s, "leg") || has(s, "shin") || has(s, "calf") || has(s, "knee")) return Part::Shin;
  if (has(s, "head")) return Part::Head;
  if (has(s, "neck")) return Part::Neck;
  if (has(s, "spine") || has(s, "back") || has(s, "chest") || has(s, "hip") || has(s, "pelvis") ||
      has(s, "root") || has(s, "torso") || has(s, "abdomen"))
    return Part::Torso;
  return Part::Other;
}

// Elliptic tapered capsule from a to b (semi-axes along ex/ez interpolated from the a-end
// to the b-end), or an ellipsoid (a = centre, axes ex/ey/ez). Approximate distances.
struct Prim {
  bool ellipsoid = false;
  Vec3 a = Vec3::Zero(), b = Vec3::Zero(), ex = Vec3::UnitX(), ey = Vec3::UnitY(), ez = Vec3::UnitZ();
  double rax = 0, raz = 0, rbx = 0, rbz = 0;  // capsule
  Vec3 r = Vec3::Ones();                      // ellipsoid semi-axes
  int owner = -1;                             // node; -1 = torso (spine chain by height)

  double sdf(const Vec3& p) const {
    if (ellipsoid) {
      const Vec3 d = p - a;
      const Vec3 q(d.dot(ex) / r.x(), d.dot(ey) / r.y(), d.dot(ez) / r.z());
      const double k0 = q.norm();
      const double k1 = Vec3(q.x() / r.x(), q.y() / r.y(), q.z() / r.z()).norm();
      if (k1 < 1e-12) return -r.minCoeff();
      return k0 * (k0 - 1.0) / k1;
    }
    const Vec3 ab = b - a;
    const double L = ab.norm();
    const Vec3 u = ab / L;
    const double t = (p - a).dot(u);
    const double tc = std::clamp(t, 0.0, L);
    const double s = tc / L;
    const double rx = rax + s * (rbx - rax), rz = raz + s * (rbz - raz);
    const Vec3 d = p - (a + u * tc);
    const double rc = std::min(rx, rz);
    const double dx = d.dot(ex) / rx, dz = d.dot(ez) / rz, de = (t - tc) / rc;
    return (std::sqrt(dx * dx + dz * dz + de * de) - 1.0) * rc;
  }
};

double smin(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

Prim capsule(const Vec3& a, const Vec3& b, double ra, double rb, int owner, const Vec3& lateral) {
  Prim p;
  p.a = a;
  p.b = b;
  const Vec3 u = (b - a).normalized();
  Vec3 ex = lateral - u * u.dot(lateral);
  if (ex.norm() < 1e-6) ex = u.unitOrthogonal();
  p.ex = ex.normalized();
  p.ez = u.cross(p.ex);
  p.rax = p.raz = ra;
  p.rbx = p.rbz = rb;
  p.owner = owner;
  return p;
}

}  // namespace

SkinnedBody build_skeleton_body(const std::vector<SkelNode>& nodes_in, double mpu, double edge) {
  const int n = static_cast<int>(nodes_in.size());
  if (n < 2) throw std::runtime_error("build_skeleton_body: skeleton has fewer than 2 nodes");
  // Work in metres relative to the root.
  const Vec3 origin = nodes_in[0].pos;
  std::vector<Vec3> P(n);
  for (int i = 0; i < n; ++i) P[i] = (nodes_in[i].pos - origin) * mpu;
  std::vector<std::vector<int>> children(n);
  for (int i = 1; i < n; ++i)
    if (nodes_in[i].parent >= 0) children[nodes_in[i].parent].push_back(i);
  std::vector<Part> part(n);
  for (int i = 0; i < n; ++i) part[i] = classify(nodes_in[i].name);

  // Landmarks: thigh starts (hip joints), upper-arm starts (shoulder joints), first neck node.
  std::vector<int> thighs, arms;
  int neck = -1, head = -1;
  for (int i = 0; i < n; ++i) {
    if (part[i] == Part::Thigh && (nodes_in[i].parent < 0 || part[nodes_in[i].parent] != Part::Thigh))
      thighs.push_back(i);
    if (part[i] == Part::UpperArm && (nodes_in[i].parent < 0 || part[nodes_in[i].parent] != Part::UpperArm))
      arms.push_back(i);
    if (part[i] == Part::Neck && neck < 0) neck = i;
    if (part[i] == Part::Head && head < 0) head = i;
  }
  const Vec3 up(0, 1, 0);
  Vec3 lateral(1, 0, 0);
  if (thighs.size() >= 2) {
    Vec3 l = P[thighs[0]] - P[thighs[1]];
    l -= up * up.dot(l);
    if (l.norm() > 1e-6) lateral = l.normalized();
  }

  std::vector<Prim> prims;
  // Descendant farthest from node i (end of a chain such as a hand).
  auto farthest_desc = [&](int i) {
    int best = i;
    double bd = 0;
    std::vector<int> st{i};
    while (!st.empty()) {
      int k = st.back();
      st.pop_back();
      double d = (P[k] - P[i]).norm();
      if (d > bd) bd = d, best = k;
      for (int c : children[k]) st.push_back(c);
    }
    return best;
  };

  SkinnedBody out;
  const bool torso_ok = thighs.size() >= 2 && arms.size() >= 2;
  Vec3 hip_mid = Vec3::Zero(), sh_mid = Vec3::Zero();
  if (torso_ok) {
    hip_mid = 0.5 * (P[thighs[0]] + P[thighs[1]]);
    sh_mid = 0.5 * (P[arms[0]] + P[arms[1]]);
    const double hip_half = 0.5 * (P[thighs[0]] - P[thighs[1]]).norm();
    const Vec3 axis = sh_mid - hip_mid;
    // Sections: (centre, lateral semi-axis, front-back semi-axis), metres.
    struct Sec { Vec3 c; double a, b; };
    const Sec pel{hip_mid + up * 0.03, std::max(0.175, hip_half + 0.085), 0.12};
    const Sec wst{hip_mid + axis * 0.40, 0.135, 0.098};
    const Sec chs{hip_mid + axis * 0.72, 0.16, 0.112};
    const Sec top{sh_mid - up * 0.03, 0.14, 0.085};
    const Sec secs[4] = {pel, wst, chs, top};
    for (int k = 0; k < 3; ++k) {
      Prim p = capsule(secs[k].c, secs[k + 1].c, 1, 1, -1, lateral);
      p.rax = secs[k].a, p.raz = secs[k].b, p.rbx = secs[k + 1].a, p.rbz = secs[k + 1].b;
      prims.push_back(p);
    }
    out.hip_y = pel.c.y(), out.waist_y = wst.c.y(), out.chest_y = chs.c.y();
    out.hip_c = pel.c, out.waist_c = wst.c, out.chest_c = chs.c;
    out.shoulder_y = sh_mid.y();
    // Straight-leg length vs its vertical extent at rest (hip joint -> first foot node).
    double extra = 0;
    int legs = 0;
    for (int t : thighs) {
      int k = t;
      while (k >= 0 && part[k] != Part::Foot) {
        int next = -1;
        for (int c : children[k])
          if (part[c] == Part::Thigh || part[c] == Part::Shin || part[c] == Part::Foot) next = c;
        k = next;
      }
      if (k < 0) continue;
      extra += (P[k] - P[t]).norm() - (P[t].y() - P[k].y());
      ++legs;
    }
    if (legs > 0) out.leg_extra = std::max(0.0, extra / legs);
  }

  for (int i = 0; i < n; ++i) {
    const Part pt = part[i];
    if (pt == Part::Skip) continue;
    if (pt == Part::Head) {
      const int e = farthest_desc(i);
      Vec3 dir = (e != i) ? (P[e] - P[i]).normalized() : up;
      Prim p;
      p.ellipsoid = true;
      p.ey = dir;
      Vec3 ex = lateral - dir * dir.dot(lateral);
      p.ex = ex.normalized();
      p.ez = p.ex.cross(p.ey);
      p.r = Vec3(0.078, 0.11, 0.095);
      const Vec3 top = (e != i) ? P[e] : P[i] + up * 0.2;
      p.a = top - dir * 0.105;
      p.owner = i;
      prims.push_back(p);
      continue;
    }
    if (pt == Part::Hand) {
      const int e = farthest_desc(i);
      Vec3 b = (e != i && (P[e] - P[i]).norm() > 0.05) ? P[e] : P[i];
      if (e == i) {
        // no fingers: extend along the parent bone
        const int par = nodes_in[i].parent;
        Vec3 d = par >= 0 ? (P[i] - P[par]) : up;
        b = P[i] + d.normalized() * 0.15;
      }
      prims.push_back(capsule(P[i], P[i] + (b - P[i]) * 0.85, 0.033, 0.024, i, up));
      continue;
    }
    if (pt == Part::Torso && torso_ok) continue;  // covered by the torso sections
    for (int c : children[i]) {
      if (part[c] == Part::Skip && classify(nodes_in[c].name) == Part::Skip &&
          !has(lower(nodes_in[c].name), "end"))
        continue;
      const double L = (P[c] - P[i]).norm();
      if (L < 1e-3) continue;
      double ra, rb;
      switch (pt) {
        case Part::Thigh: ra = 0.082, rb = 0.055; break;
        case Part::Shin: ra = 0.054, rb = 0.038; break;
        case Part::Foot: ra = 0.042, rb = 0.034; break;
        case Part::Toe: ra = 0.033, rb = 0.026; break;
        case Part::Clavicle: ra = 0.065, rb = 0.052; break;
        case Part::UpperArm: ra = 0.05, rb = 0.039; break;
        case Part::ForeArm: ra = 0.039, rb = 0.029; break;
        case Part::Neck: ra = 0.058, rb = 0.052; break;
        case Part::Torso: ra = rb = 0.12; break;
        default: ra = rb = std::clamp(0.15 * L, 0.015, 0.06); break;
      }
      prims.push_back(capsule(P[i], P[c], ra, rb, i, up));
    }
  }
  if (prims.empty()) throw std::runtime_error("build_skeleton_body: no bones with length found");

  // Spine chain (root .. neck parent) with control heights for the torso weights.
  std::vector<std::pair<double, int>> chain;  // (height, node)
  if (neck >= 0) {
    std::vector<int> path;
    for (int k = nodes_in[neck].parent; k >= 0; k = nodes_in[k].parent) path.push_back(k);
    std::reverse(path.begin(), path.end());
    for (size_t j = 0; j < path.size(); ++j) {
      const int k = path[j];
      const Vec3 next = (j + 1 < path.size()) ? P[path[j + 1]] : P[neck];
      double yc;
      if (j == 0) yc = torso_ok ? hip_mid.y() : P[k].y();
      else if ((next - P[k]).norm() > 1e-3) yc = 0.5 * (next.y() + P[k].y());
      else if (j + 1 == path.size()) yc = P[k].y() + 0.08;
      else continue;
      if (!chain.empty() && yc <= chain.back().first) chain.back().second = k;
      else chain.push_back({yc, k});
    }
  }
  if (chain.empty()) chain.push_back({0.0, 0});

  auto field = [&](const Vec3& p) {
    double d = prims[0].sdf(p);
    for (size_t i = 1; i < prims.size(); ++i) d = smin(d, prims[i].sdf(p), 0.03);
    return d;
  };

  // Deterministic meshing: marching tetrahedra on a grid (closed, manifold piecewise-linear
  // isosurface), then CGAL isotropic remeshing to the target edge length, then vertices
  // projected back onto the smooth field.
  Vec3 blo = Vec3::Constant(1e300), bhi = Vec3::Constant(-1e300);
  for (const Prim& p : prims) {
    const double rmax = p.ellipsoid ? p.r.maxCoeff() : std::max({p.rax, p.raz, p.rbx, p.rbz});
    for (const Vec3& c : {p.a, p.ellipsoid ? p.a : p.b}) {
      blo = blo.cwiseMin(c - Vec3::Constant(rmax));
      bhi = bhi.cwiseMax(c + Vec3::Constant(rmax));
    }
  }
  const double h = std::min(0.015, 0.6 * edge);
  blo -= Vec3::Constant(2 * h);
  bhi += Vec3::Constant(2 * h);
  const int gx = static_cast<int>(std::ceil((bhi.x() - blo.x()) / h)) + 1;
  const int gy = static_cast<int>(std::ceil((bhi.y() - blo.y()) / h)) + 1;
  const int gz = static_cast<int>(std::ceil((bhi.z() - blo.z()) / h)) + 1;
  auto gid = [&](int i, int j, int k) { return (static_cast<long long>(k) * gy + j) * gx + i; };
  auto gpos = [&](long long g) {
    const int i = static_cast<int>(g % gx), j = static_cast<int>((g / gx) % gy), k = static_cast<int>(g / (static_cast<long long>(gx) * gy));
    return Vec3(blo.x() + i * h, blo.y() + j * h, blo.z() + k * h);
  };
  std::vector<double> val(static_cast<size_t>(gx) * gy * gz);
#pragma omp parallel for schedule(dynamic)
  for (int k = 0; k < gz; ++k)
    for (int j = 0; j < gy; ++j)
      for (int i = 0; i < gx; ++i) {
        double f = field(Vec3(blo.x() + i * h, blo.y() + j * h, blo.z() + k * h));
        if (f == 0) f = 1e-12;  // no vertex exactly on the surface
        val[gid(i, j, k)] = f;
      }
  std::vector<Vec3> mv;
  std::vector<std::array<int, 3>> mf;
  std::unordered_map<long long, int> edge_vertex;
  const long long ng = static_cast<long long>(gx) * gy * gz;
  auto crossing = [&](long long a, long long b) {
    if (a > b) std::swap(a, b);
    auto [it, fresh] = edge_vertex.emplace(a * ng + b, static_cast<int>(mv.size()));
    if (fresh) {
      const double fa = val[a], fb = val[b];
      mv.push_back(gpos(a) + (fa / (fa - fb)) * (gpos(b) - gpos(a)));
    }
    return it->second;
  };
  // Freudenthal split of the cube into 6 tetrahedra around the diagonal 0-7 (corner bits x=1, y=2, z=4).
  static const int tets[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7}, {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
  auto emit = [&](int a, int b, int c, const Vec3& out_dir) {
    const Vec3 n = (mv[b] - mv[a]).cross(mv[c] - mv[a]);
    if (n.dot(out_dir) >= 0) mf.push_back({a, b, c});
    else mf.push_back({a, c, b});
  };
  for (int k = 0; k + 1 < gz; ++k)
    for (int j = 0; j + 1 < gy; ++j)
      for (int i = 0; i + 1 < gx; ++i) {
        long long g[8];
        int neg = 0;
        for (int c = 0; c < 8; ++c) {
          g[c] = gid(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
          neg += val[g[c]] < 0;
        }
        if (neg == 0 || neg == 8) continue;
        for (const auto& t : tets) {
          std::vector<long long> in, out;
          for (int c : t) (val[g[c]] < 0 ? in : out).push_back(g[c]);
          if (in.empty() || out.empty()) continue;
          Vec3 dir = Vec3::Zero();
          for (long long q : out) dir += gpos(q) / out.size();
          for (long long q : in) dir -= gpos(q) / in.size();
          if (in.size() == 1 || out.size() == 1) {
            const long long lone = in.size() == 1 ? in[0] : out[0];
            const auto& rest = in.size() == 1 ? out : in;
            emit(crossing(lone, rest[0]), crossing(lone, rest[1]), crossing(lone, rest[2]), dir);
          } else {
            const int ac = crossing(in[0], out[0]), ad = crossing(in[0], out[1]);
            const int bd = crossing(in[1], out[1]), bc = crossing(in[1], out[0]);
            emit(ac, ad, bd, dir);
            emit(ac, bd, bc, dir);
          }
        }
      }
  if (mf.size() < 4) throw std::runtime_error("build_skeleton_body: marching tetrahedra found no surface");

  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using SM = CGAL::Surface_mesh<K::Point_3>;
  SM sm;
  std::vector<SM::Vertex_index> vh;
  vh.reserve(mv.size());
  for (const Vec3& p : mv) vh.push_back(sm.add_vertex(K::Point_3(p.x(), p.y(), p.z())));
  for (const auto& t : mf) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    if (sm.add_face(vh[t[0]], vh[t[1]], vh[t[2]]) == SM::null_face())
      throw std::runtime_error("build_skeleton_body: marching tetrahedra produced a non-manifold face");
  }
  namespace PMP = CGAL::Polygon_mesh_processing;
  PMP::isotropic_remeshing(faces(sm), edge, sm, CGAL::parameters::number_of_iterations(4));
  sm.collect_garbage();
  if (sm.number_of_faces() < 4) throw std::runtime_error("build_skeleton_body: remeshing failed");

  const int nv = static_cast<int>(sm.number_of_vertices());
  Points3 V(nv, 3);
  for (auto v : sm.vertices()) {
    const auto& q = sm.point(v);
    V.row(static_cast<int>(v.idx())) << q.x(), q.y(), q.z();
  }
  Faces F(sm.number_of_faces(), 3);
  int k = 0;
  for (auto f : sm.faces()) {
    int j = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) F(k, j++) = static_cast<int>(v.idx());
    ++k;
  }
  // Newton steps onto the zero set of the smooth field (central-difference gradient).
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    Vec3 p = V.row(i);
    for (int it = 0; it < 3; ++it) {
      const double f = field(p), e = 1e-4;
      Vec3 g;
      for (int c = 0; c < 3; ++c) {
        Vec3 d = Vec3::Zero();
        d[c] = e;
        g[c] = (field(p + d) - field(p - d)) / (2 * e);
      }
      const double gg = g.squaredNorm();
      if (!(gg > 1e-8)) break;
      Vec3 step = g * (f / gg);
      if (step.norm() > 0.25 * edge) step *= 0.25 * edge / step.norm();
      p -= step;
    }
    V.row(i) = p.transpose();
  }
  // Outward orientation: positive signed volume.
  double vol = 0;
  for (int f = 0; f < F.rows(); ++f)
    vol += Vec3(V.row(F(f, 0))).dot(Vec3(V.row(F(f, 1))).cross(Vec3(V.row(F(f, 2)))));
  if (vol < 0) F.col(1).swap(F.col(2));

  // Skin weights: soft assignment to primitives by distance, torso split along the spine.
  const double tau = 0.015;
  out.skin_start.assign(1, 0);
  for (int i = 0; i < nv; ++i) {
    const Vec3 p = V.row(i);
    std::vector<double> d(prims.size());
    double dmin = 1e30;
    for (size_t j = 0; j < prims.size(); ++j) dmin = std::min(dmin, d[j] = prims[j].sdf(p));
    std::map<int, double> acc;
    for (size_t j = 0; j < prims.size(); ++j) {
      if (d[j] > dmin + 5 * tau) continue;
      const double w = std::exp(-(d[j] - dmin) / tau);
      if (prims[j].owner >= 0) {
        acc[prims[j].owner] += w;
        continue;
      }
      const double y = p.y();
      if (y <= chain.front().first) acc[chain.front().second] += w;
      else if (y >= chain.back().first) acc[chain.back().second] += w;
      else
        for (size_t c = 0; c + 1 < chain.size(); ++c)
          if (y >= chain[c].first && y <= chain[c + 1].first) {
            const double s = (y - chain[c].first) / (chain[c + 1].first - chain[c].first);
            acc[chain[c].second] += w * (1 - s);
            acc[chain[c + 1].second] += w * s;
            break;
          }
    }
    std::vector<std::pair<double, int>> ws;
    for (auto& [node, w] : acc) ws.push_back({w, node});
    std::sort(ws.rbegin(), ws.rend());
    if (ws.size() > 4) ws.resize(4);
    double tot = 0;
    for (auto& w : ws) tot += w.first;
    for (auto& w : ws) {
      out.skin_node.push_back(w.second);
      out.skin_weight.push_back(w.first / tot);
    }
    out.skin_start.push_back(static_cast<int>(out.skin_node.size()));
  }

  // Back to file units.
  out.V = V / mpu;
  out.V.rowwise() += origin.transpose();
  out.F = F;
  auto to_file = [&](const Vec3& c) { return Vec3(c / mpu + origin); };
  out.hip_y = out.hip_y / mpu + origin.y();
  out.waist_y = out.waist_y / mpu + origin.y();
  out.chest_y = out.chest_y / mpu + origin.y();
  out.shoulder_y = out.shoulder_y / mpu + origin.y();
  out.leg_extra /= mpu;
  out.hip_c = to_file(out.hip_c), out.waist_c = to_file(out.waist_c), out.chest_c = to_file(out.chest_c);
  if (!torso_ok) {
    // Fractions of the height as a fallback.
    const double y0 = out.V.col(1).minCoeff(), h = out.V.col(1).maxCoeff() - y0;
    const Vec3 c = 0.5 * (out.V.colwise().minCoeff() + out.V.colwise().maxCoeff()).transpose();
    out.hip_y = y0 + 0.52 * h, out.waist_y = y0 + 0.61 * h, out.chest_y = y0 + 0.72 * h;
    out.shoulder_y = y0 + 0.82 * h;
    out.hip_c = Vec3(c.x(), out.hip_y, c.z());
    out.waist_c = Vec3(c.x(), out.waist_y, c.z());
    out.chest_c = Vec3(c.x(), out.chest_y, c.z());
  }
  return out;
}

}  // namespace gdsr::detail

// A human-like body around a bare skeleton: bones are classified by name (CMU/Mixamo
// style names), limbs become tapered capsules, the torso a stack of elliptic capsules
// through landmarks (hip joints, shoulder joints, neck), the head an ellipsoid. Their
// smooth union is meshed once at the rest pose (gdsr/geometry/implicit_mesher: closed,
// manifold, deterministic); vertices are skinned to the bones owning the nearest primitives.
#include "gdsr/body/skeleton_body.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/implicit_mesher.hpp"

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
  if (has(s, "finger") || has(s, "thumb") || has(s, "index") || has(s, "pinky") || has(s, "ring") || has(s, "middle") ||
      has(s, "endsite") || has(s, "_end"))
    return Part::Skip;
  // root -> hip joint: inside the pelvis (CMU ASF "LHipJoint", Poser "lButtock")
  if (has(s, "hipjoint") || has(s, "buttock")) return Part::Skip;
  if (has(s, "hand") || has(s, "wrist")) return Part::Hand;
  if (has(s, "forearm") || has(s, "lowerarm") || has(s, "elbow")) return Part::ForeArm;
  // Poser / CMU salsa names: "rCollar" (clavicle) then "rShldr" (the upper arm). Unrecognised,
  // the body had no shoulder joints and its torso became a shoulderless column.
  if (has(s, "shldr")) return Part::UpperArm;
  if (has(s, "shoulder") || has(s, "clavicle") || has(s, "collar")) return Part::Clavicle;
  if (has(s, "arm")) return Part::UpperArm;
  // A sided "hip" is the thigh (CMU cgspeed naming, e.g. the 131 walks: "LeftHip" -> "LeftKnee"); the
  // unsided "Hips" is the pelvis.
  if (has(s, "upleg") || has(s, "thigh") || has(s, "upperleg") || s == "lefthip" || s == "righthip" ||
      s == "left_hip" || s == "right_hip")
    return Part::Thigh;
  if (has(s, "toe")) return Part::Toe;
  if (has(s, "foot") || has(s, "ankle")) return Part::Foot;
  if (has(s, "leg") || has(s, "shin") || has(s, "calf") || has(s, "knee")) return Part::Shin;
  if (has(s, "head")) return Part::Head;
  if (has(s, "neck")) return Part::Neck;
  if (has(s, "spine") || has(s, "back") || has(s, "chest") || has(s, "hip") || has(s, "pelvis") || has(s, "root") ||
      has(s, "torso") || has(s, "abdomen"))
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

// The skeleton in metres relative to its root, with each node's body part and the landmark
// joints (hips, shoulders, neck).
struct Skeleton {
  std::vector<Vec3> P;
  std::vector<std::vector<int>> children;
  std::vector<Part> part;
  std::vector<int> thighs, arms;
  int neck = -1, head = -1;
  Vec3 lateral = Vec3::UnitX();  // left-right direction of the hips
  bool torso_ok = false;         // two hips and two shoulders found
  Vec3 hip_mid = Vec3::Zero(), sh_mid = Vec3::Zero();
};

const Vec3 kUp(0, 1, 0);

Skeleton analyse(const std::vector<SkelNode>& nodes_in, double mpu) {
  Skeleton sk;
  const int n = static_cast<int>(nodes_in.size());
  // Work in metres relative to the root.
  const Vec3 origin = nodes_in[0].pos;
  std::vector<Vec3> P(n);
  for (int i = 0; i < n; ++i) P[i] = (nodes_in[i].pos - origin) * mpu;
  std::vector<std::vector<int>> children(n);
  for (int i = 1; i < n; ++i)
    if (nodes_in[i].parent >= 0) children[nodes_in[i].parent].push_back(i);
  std::vector<Part> part(n);
  for (int i = 0; i < n; ++i) part[i] = classify(nodes_in[i].name);
  // A "shoulder" below a collar is the upper arm (cgspeed: "LeftCollar" -> "LeftShoulder" ->
  // "LeftElbow"); below the spine it is the clavicle (CMU ASF: "LeftShoulder" -> "LeftArm").
  for (int i = 0; i < n; ++i)
    if (part[i] == Part::Clavicle && nodes_in[i].parent >= 0 && part[nodes_in[i].parent] == Part::Clavicle)
      part[i] = Part::UpperArm;

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

  sk.P = P;
  sk.children = children;
  sk.part = part;
  sk.thighs = thighs;
  sk.arms = arms;
  sk.neck = neck;
  sk.head = head;
  sk.lateral = lateral;
  sk.torso_ok = sk.thighs.size() >= 2 && sk.arms.size() >= 2;
  if (sk.torso_ok) {
    sk.hip_mid = 0.5 * (sk.P[sk.thighs[0]] + sk.P[sk.thighs[1]]);
    sk.sh_mid = 0.5 * (sk.P[sk.arms[0]] + sk.P[sk.arms[1]]);
  }
  return sk;
}

// The torso as three elliptic capsules through pelvis, waist, chest and shoulder sections
// (radii in metres); records the landmarks and the legs' extra standing height in out.
void add_torso(const Skeleton& sk, std::vector<Prim>& prims, SkinnedBody& out) {
  const auto& P = sk.P;
  const auto& children = sk.children;
  const auto& part = sk.part;
  const Vec3& up = kUp;
  const auto& thighs = sk.thighs;
  const Vec3& lateral = sk.lateral;
  const Vec3 &hip_mid = sk.hip_mid, &sh_mid = sk.sh_mid;
  {
    const double hip_half = 0.5 * (P[thighs[0]] - P[thighs[1]]).norm();
    const Vec3 axis = sh_mid - hip_mid;
    // Sections: (centre, lateral semi-axis, front-back semi-axis), metres.
    struct Sec {
      Vec3 c;
      double a, b;
    };
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
}

// Head (ellipsoid), hands and every other bone (tapered capsules); torso bones only when
// the torso sections are missing.
void add_limbs(const Skeleton& sk, const std::vector<SkelNode>& nodes_in, std::vector<Prim>& prims) {
  const auto& P = sk.P;
  const auto& children = sk.children;
  const auto& part = sk.part;
  const Vec3& up = kUp;
  const Vec3& lateral = sk.lateral;
  const int n = static_cast<int>(P.size());
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
  for (int i = 0; i < n; ++i) {
    const Part pt = part[i];
    if (pt == Part::Skip) continue;
    if (pt == Part::Head) {
      int e = farthest_desc(i);
      Vec3 dir = (e != i) ? (P[e] - P[i]).normalized() : up;
      // The head's end site gives its axis. Eyes alone (Poser / CMU salsa: "leftEye", forward and
      // to one side, 42 degrees off the neck) would tilt it onto a shoulder: the neck's direction.
      const int par = nodes_in[i].parent;
      if (e != i && par >= 0 && (P[i] - P[par]).norm() > 1e-3 && dir.dot((P[i] - P[par]).normalized()) < 0.9) {
        dir = (P[i] - P[par]).normalized();
        e = i;
      }
      Prim p;
      p.ellipsoid = true;
      p.ey = dir;
      Vec3 ex = lateral - dir * dir.dot(lateral);
      p.ex = ex.normalized();
      p.ez = p.ex.cross(p.ey);
      p.r = Vec3(0.078, 0.11, 0.095);
      const Vec3 top = (e != i) ? P[e] : P[i] + dir * 0.2;
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
    if (pt == Part::Torso && sk.torso_ok) continue;  // covered by the torso sections
    for (int c : children[i]) {
      if (part[c] == Part::Skip && classify(nodes_in[c].name) == Part::Skip && !has(lower(nodes_in[c].name), "end"))
        continue;
      const double L = (P[c] - P[i]).norm();
      if (L < 1e-3) continue;
      double ra, rb;
      switch (pt) {
        case Part::Thigh:
          ra = 0.082, rb = 0.055;
          break;
        case Part::Shin:
          ra = 0.054, rb = 0.038;
          break;
        case Part::Foot:
          ra = 0.042, rb = 0.034;
          break;
        case Part::Toe:
          ra = 0.033, rb = 0.026;
          break;
        case Part::Clavicle:
          ra = 0.065, rb = 0.052;
          break;
        case Part::UpperArm:
          ra = 0.05, rb = 0.039;
          break;
        case Part::ForeArm:
          ra = 0.039, rb = 0.029;
          break;
        case Part::Neck:
          ra = 0.058, rb = 0.052;
          break;
        case Part::Torso:
          ra = rb = 0.12;
          break;
        default:
          ra = rb = std::clamp(0.15 * L, 0.015, 0.06);
          break;
      }
      prims.push_back(capsule(P[i], P[c], ra, rb, i, up));
    }
  }
  if (prims.empty()) gdsr::fail("build_skeleton_body", "no bones with length found");
}

// Spine chain (root .. neck parent) as (control height, node), increasing heights: the
// torso's skin weights are interpolated along it.
std::vector<std::pair<double, int>> spine_chain(const Skeleton& sk, const std::vector<SkelNode>& nodes_in) {
  const auto& P = sk.P;
  const int neck = sk.neck;
  std::vector<std::pair<double, int>> chain;  // (height, node)
  if (neck >= 0) {
    std::vector<int> path;
    for (int k = nodes_in[neck].parent; k >= 0; k = nodes_in[k].parent) path.push_back(k);
    std::reverse(path.begin(), path.end());
    for (size_t j = 0; j < path.size(); ++j) {
      const int k = path[j];
      const Vec3 next = (j + 1 < path.size()) ? P[path[j + 1]] : P[neck];
      double yc;
      if (j == 0)
        yc = sk.torso_ok ? sk.hip_mid.y() : P[k].y();
      else if ((next - P[k]).norm() > 1e-3)
        yc = 0.5 * (next.y() + P[k].y());
      else if (j + 1 == path.size())
        yc = P[k].y() + 0.08;
      else
        continue;
      if (!chain.empty() && yc <= chain.back().first)
        chain.back().second = k;
      else
        chain.push_back({yc, k});
    }
  }
  if (chain.empty()) chain.push_back({0.0, 0});

  return chain;
}

// Skin weights: soft assignment to primitives by distance, torso split along the spine;
// at most 4 nodes per vertex.
void skin(const Points3& V, const std::vector<Prim>& prims, const std::vector<std::pair<double, int>>& chain,
          SkinnedBody& out) {
  const int nv = static_cast<int>(V.rows());
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
      if (y <= chain.front().first)
        acc[chain.front().second] += w;
      else if (y >= chain.back().first)
        acc[chain.back().second] += w;
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
}

// Back from metres relative to the root to file units; height fractions as landmarks when
// the torso was not recognised.
void to_file_units(SkinnedBody& out, double mpu, const Vec3& origin, bool torso_ok) {
  out.V /= mpu;
  out.V.rowwise() += origin.transpose();
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
}

}  // namespace

std::vector<int> upper_arm_starts(const std::vector<SkelNode>& nodes) {
  if (nodes.size() < 2) return {};
  return analyse(nodes, 1.0).arms;
}

std::vector<int> limb_segments(const std::vector<SkelNode>& nodes) {
  const int n = static_cast<int>(nodes.size());
  std::vector<int> seg(n, -1);
  if (n < 2) return seg;
  const Skeleton sk = analyse(nodes, 1.0);
  auto limb = [](Part p) { return p == Part::UpperArm || p == Part::ForeArm || p == Part::Thigh || p == Part::Shin; };
  for (int i = 0; i < n; ++i) {  // parents come before children
    const int par = nodes[i].parent;
    if (limb(sk.part[i]))
      seg[i] = par >= 0 && sk.part[par] == sk.part[i] ? seg[par] : i;
    else if (par >= 0 && sk.part[i] != Part::Torso && sk.part[i] != Part::Clavicle)
      seg[i] = seg[par];
  }
  return seg;
}

SkinnedBody build_skeleton_body(const std::vector<SkelNode>& nodes_in, double mpu, double edge) {
  if (nodes_in.size() < 2) gdsr::fail("build_skeleton_body", "skeleton has fewer than 2 nodes");
  const Skeleton sk = analyse(nodes_in, mpu);
  std::vector<Prim> prims;
  SkinnedBody out;
  if (sk.torso_ok) add_torso(sk, prims, out);
  add_limbs(sk, nodes_in, prims);
  if (prims.empty()) gdsr::fail("build_skeleton_body", "no bones with length found");
  const std::vector<std::pair<double, int>> chain = spine_chain(sk, nodes_in);

  auto field = [&](const Vec3& p) {
    double d = prims[0].sdf(p);
    for (size_t i = 1; i < prims.size(); ++i) d = smin(d, prims[i].sdf(p), 0.03);
    return d;
  };
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Prim& p : prims) {
    const double rmax = p.ellipsoid ? p.r.maxCoeff() : std::max({p.rax, p.raz, p.rbx, p.rbz});
    for (const Vec3& c : {p.a, p.ellipsoid ? p.a : p.b}) {
      lo = lo.cwiseMin(c - Vec3::Constant(rmax));
      hi = hi.cwiseMax(c + Vec3::Constant(rmax));
    }
  }
  const TriMesh m = mesh_implicit(field, lo, hi, std::min(0.015, 0.6 * edge), edge);
  skin(m.V, prims, chain, out);
  out.V = m.V;
  out.F = m.F;
  to_file_units(out, mpu, nodes_in[0].pos, sk.torso_ok);
  out.torso_found = sk.torso_ok;
  return out;
}

}  // namespace gdsr::detail

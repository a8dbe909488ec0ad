#include "gdsr/body/body.hpp"

#include "gdsr/error.hpp"

#include "gdsr/body/body_query.hpp"
#include "gdsr/body/body_yield.hpp"
#include "gdsr/body/skeleton_body.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>

namespace gdsr {
namespace {

using Mat4 = Eigen::Matrix4d;
using Quat = Eigen::Quaterniond;

Mat4 to_eigen(const aiMatrix4x4& m) {
  Mat4 r;
  r << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return r;
}

struct Trs {
  Vec3 t = Vec3::Zero();
  Quat r = Quat::Identity();
  Vec3 s = Vec3::Ones();
  Mat4 matrix() const {
    Mat4 m = Mat4::Identity();
    m.topLeftCorner<3, 3>() = r.toRotationMatrix() * s.asDiagonal();
    m.topRightCorner<3, 1>() = t;
    return m;
  }
};

Trs decompose(const aiMatrix4x4& m) {
  aiVector3D s, p;
  aiQuaternion q;
  m.Decompose(s, q, p);
  Trs r;
  r.t = Vec3(p.x, p.y, p.z);
  r.r = Quat(q.w, q.x, q.y, q.z).normalized();
  r.s = Vec3(s.x, s.y, s.z);
  return r;
}

template <class Key> int bracket(const Key* keys, unsigned n, double tick) {  // last key with time <= tick
  if (n == 0 || tick <= keys[0].mTime) return 0;
  int lo = 0, hi = static_cast<int>(n) - 1;
  if (tick >= keys[hi].mTime) return hi;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    (keys[mid].mTime <= tick ? lo : hi) = mid;
  }
  return lo;
}

template <class Key> double frac(const Key* keys, unsigned n, int i, double tick) {
  if (i + 1 >= static_cast<int>(n)) return 0;
  const double dt = keys[i + 1].mTime - keys[i].mTime;
  return dt > 0 ? std::clamp((tick - keys[i].mTime) / dt, 0.0, 1.0) : 0.0;
}

// The channel's keys at `tick`; parts without keys keep `rest`'s. `moved` is added to the
// position keys (a joint moved in its parent's frame, already in `rest`).
Trs sample(const aiNodeAnim* ch, double tick, const Trs& rest, const Vec3& moved) {
  Trs r = rest;
  if (ch->mNumPositionKeys > 0) {
    const int i = bracket(ch->mPositionKeys, ch->mNumPositionKeys, tick);
    const double a = frac(ch->mPositionKeys, ch->mNumPositionKeys, i, tick);
    const auto& k0 = ch->mPositionKeys[i].mValue;
    const auto& k1 = ch->mPositionKeys[std::min<int>(i + 1, ch->mNumPositionKeys - 1)].mValue;
    r.t = (1 - a) * Vec3(k0.x, k0.y, k0.z) + a * Vec3(k1.x, k1.y, k1.z) + moved;
  }
  if (ch->mNumRotationKeys > 0) {
    const int i = bracket(ch->mRotationKeys, ch->mNumRotationKeys, tick);
    const double a = frac(ch->mRotationKeys, ch->mNumRotationKeys, i, tick);
    const auto& k0 = ch->mRotationKeys[i].mValue;
    const auto& k1 = ch->mRotationKeys[std::min<int>(i + 1, ch->mNumRotationKeys - 1)].mValue;
    const Quat q0(k0.w, k0.x, k0.y, k0.z), q1(k1.w, k1.x, k1.y, k1.z);
    r.r = q0.normalized().slerp(a, q1.normalized());
  }
  if (ch->mNumScalingKeys > 0) {
    const int i = bracket(ch->mScalingKeys, ch->mNumScalingKeys, tick);
    const double a = frac(ch->mScalingKeys, ch->mNumScalingKeys, i, tick);
    const auto& k0 = ch->mScalingKeys[i].mValue;
    const auto& k1 = ch->mScalingKeys[std::min<int>(i + 1, ch->mNumScalingKeys - 1)].mValue;
    r.s = (1 - a) * Vec3(k0.x, k0.y, k0.z) + a * Vec3(k1.x, k1.y, k1.z);
  }
  return r;
}

// Scene nodes in parent-before-child order with their rest transforms and channels.
struct Rig {
  std::vector<const aiNode*> node;
  std::vector<int> parent;
  std::vector<Trs> rest;
  std::vector<const aiNodeAnim*> channel;
  std::vector<Vec3> moved;  // per node: offset added to its translation in every pose (file units)
  std::map<std::string, int> index;
  Mat4 pre = Mat4::Identity();  // up-axis fix applied above the root

  // Global transforms for the given local transforms.
  std::vector<Mat4> globals(const std::vector<Trs>& local) const {
    std::vector<Mat4> G(node.size());
    for (size_t i = 0; i < node.size(); ++i) G[i] = (parent[i] < 0 ? pre : G[parent[i]]) * local[i].matrix();
    return G;
  }
};

Mat4 up_axis_fix(const aiScene* s) {
  Mat4 m = Mat4::Identity();
  if (!s->mMetaData) return m;
  int up = 1, sign = 1;
  if (!s->mMetaData->Get("UpAxis", up)) return m;
  s->mMetaData->Get("UpAxisSign", sign);
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (up == 2)
    R = Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  else if (up == 0)
    R = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
  if (sign < 0) R = Eigen::AngleAxisd(M_PI, Vec3::UnitX()).toRotationMatrix() * R;
  m.topLeftCorner<3, 3>() = R;
  return m;
}

// Skinning: vertex v = sum_k w_k * (G[node_k] * bind_k) * p_v (p in the bind space).
struct Skin {
  Points3 P;                    // bind-space positions
  std::vector<int> start, mat;  // per vertex influences into mats
  std::vector<double> weight;
  std::vector<int> mat_node;   // matrix -> node
  std::vector<Mat4> mat_bind;  // matrix -> bind (offset) matrix
  Faces F;

  Points3 apply(const std::vector<Mat4>& G) const {
    std::vector<Mat4> M(mat_node.size());
    for (size_t m = 0; m < M.size(); ++m) M[m] = G[mat_node[m]] * mat_bind[m];
    Points3 out(P.rows(), 3);
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
      Eigen::Vector4d p(P(i, 0), P(i, 1), P(i, 2), 1.0), acc = Eigen::Vector4d::Zero();
      for (int k = start[i]; k < start[i + 1]; ++k) acc += weight[k] * (M[mat[k]] * p);
      out.row(i) = acc.head<3>().transpose();
    }
    return out;
  }
};

void collect(const aiNode* n, int parent, Rig& rig) {
  const int id = static_cast<int>(rig.node.size());
  rig.node.push_back(n);
  rig.parent.push_back(parent);
  rig.rest.push_back(decompose(n->mTransformation));
  rig.channel.push_back(nullptr);
  rig.moved.push_back(Vec3::Zero());
  rig.index[n->mName.C_Str()] = id;
  for (unsigned c = 0; c < n->mNumChildren; ++c) collect(n->mChildren[c], id, rig);
}

// Skinned meshes of the file (all meshes; meshes without bones follow their node).
Skin skin_from_meshes(const aiScene* s, const Rig& rig, const std::string& path) {
  Skin sk;
  std::vector<Vec3> P;
  std::vector<std::vector<std::pair<int, double>>> infl;
  std::vector<Eigen::Vector3i> tris;
  std::map<std::string, int> bone_mat;
  for (size_t ni = 0; ni < rig.node.size(); ++ni) {
    const aiNode* nd = rig.node[ni];
    for (unsigned mi = 0; mi < nd->mNumMeshes; ++mi) {
      const aiMesh* m = s->mMeshes[nd->mMeshes[mi]];
      const int base = static_cast<int>(P.size());
      for (unsigned v = 0; v < m->mNumVertices; ++v)
        P.emplace_back(m->mVertices[v].x, m->mVertices[v].y, m->mVertices[v].z);
      infl.resize(P.size());
      for (unsigned b = 0; b < m->mNumBones; ++b) {
        const aiBone* bone = m->mBones[b];
        auto it = rig.index.find(bone->mName.C_Str());
        if (it == rig.index.end())
          gdsr::fail("load_body_sequence: " + path, std::string("bone '") + bone->mName.C_Str() + "' has no node");
        const int mat = static_cast<int>(sk.mat_node.size());
        sk.mat_node.push_back(it->second);
        sk.mat_bind.push_back(to_eigen(bone->mOffsetMatrix));
        for (unsigned w = 0; w < bone->mNumWeights; ++w)
          if (bone->mWeights[w].mWeight > 0)
            infl[base + bone->mWeights[w].mVertexId].push_back({mat, bone->mWeights[w].mWeight});
      }
      // Vertices without weights follow the mesh's node rigidly.
      const int rigid = static_cast<int>(sk.mat_node.size());
      sk.mat_node.push_back(static_cast<int>(ni));
      sk.mat_bind.push_back(Mat4::Identity());
      for (unsigned v = 0; v < m->mNumVertices; ++v)
        if (infl[base + v].empty()) infl[base + v].push_back({rigid, 1.0});
      for (unsigned f = 0; f < m->mNumFaces; ++f)
        if (m->mFaces[f].mNumIndices == 3)
          tris.emplace_back(base + m->mFaces[f].mIndices[0], base + m->mFaces[f].mIndices[1],
                            base + m->mFaces[f].mIndices[2]);
    }
  }
  if (tris.empty()) gdsr::fail("load_body_sequence: " + path, "skinned mesh has no triangles");
  sk.P.resize(P.size(), 3);
  sk.start.push_back(0);
  for (size_t i = 0; i < P.size(); ++i) {
    sk.P.row(i) = P[i].transpose();
    double tot = 0;
    for (auto& [m, w] : infl[i]) tot += w;
    for (auto& [m, w] : infl[i]) sk.mat.push_back(m), sk.weight.push_back(w / tot);
    sk.start.push_back(static_cast<int>(sk.mat.size()));
  }
  sk.F.resize(tris.size(), 3);
  for (size_t f = 0; f < tris.size(); ++f) sk.F.row(f) = tris[f].transpose();
  return sk;
}

// Welds vertices with identical rest positions (mesh seams split by normals/UVs).
void weld(Skin& sk, const Points3& rest) {
  std::map<std::array<double, 3>, int> seen;
  std::vector<int> remap(rest.rows());
  std::vector<int> keep;
  for (Eigen::Index i = 0; i < rest.rows(); ++i) {
    std::array<double, 3> key{std::round(rest(i, 0) * 1e6), std::round(rest(i, 1) * 1e6), std::round(rest(i, 2) * 1e6)};
    auto [it, fresh] = seen.emplace(key, static_cast<int>(keep.size()));
    if (fresh) keep.push_back(static_cast<int>(i));
    remap[i] = it->second;
  }
  Skin w;
  w.mat_node = sk.mat_node;
  w.mat_bind = sk.mat_bind;
  w.P.resize(keep.size(), 3);
  w.start.push_back(0);
  for (size_t j = 0; j < keep.size(); ++j) {
    const int i = keep[j];
    w.P.row(j) = sk.P.row(i);
    for (int k = sk.start[i]; k < sk.start[i + 1]; ++k) w.mat.push_back(sk.mat[k]), w.weight.push_back(sk.weight[k]);
    w.start.push_back(static_cast<int>(w.mat.size()));
  }
  std::vector<Eigen::Vector3i> tris;
  for (Eigen::Index f = 0; f < sk.F.rows(); ++f) {
    Eigen::Vector3i t(remap[sk.F(f, 0)], remap[sk.F(f, 1)], remap[sk.F(f, 2)]);
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) tris.push_back(t);
  }
  w.F.resize(tris.size(), 3);
  for (size_t f = 0; f < tris.size(); ++f) w.F.row(f) = tris[f].transpose();
  sk = std::move(w);
}

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

// The file's animation (the one with most channels) and its rig (nodes, rest, channels).
struct Clip {
  const aiAnimation* anim = nullptr;
  Rig rig;
  double tps = 25;      // ticks per second
  double t0 = 0;        // clip start, seconds (after a skipped calibration key)
  double duration = 0;  // seconds from t0
  bool skinned = false;
};

Clip read_clip(const aiScene* s, const std::string& path, const BodyOptions& opt) {
  if (s->mNumAnimations == 0) gdsr::fail("load_body_sequence: " + path, "file has no animation");
  Clip c;
  c.anim = s->mAnimations[0];
  for (unsigned a = 1; a < s->mNumAnimations; ++a)
    if (s->mAnimations[a]->mNumChannels > c.anim->mNumChannels) c.anim = s->mAnimations[a];
  if (c.anim->mNumChannels == 0) gdsr::fail("load_body_sequence: " + path, "animation has no channels");
  collect(s->mRootNode, -1, c.rig);
  c.rig.pre = up_axis_fix(s);
  for (unsigned k = 0; k < c.anim->mNumChannels; ++k) {
    auto it = c.rig.index.find(c.anim->mChannels[k]->mNodeName.C_Str());
    if (it != c.rig.index.end()) c.rig.channel[it->second] = c.anim->mChannels[k];
  }
  std::string ext = path.substr(path.find_last_of('.') + 1);
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (ext != "bvh")
    for (unsigned m = 0; m < s->mNumMeshes; ++m) c.skinned = c.skinned || s->mMeshes[m]->mNumBones > 0;

  c.tps = c.anim->mTicksPerSecond > 0 ? c.anim->mTicksPerSecond : 25.0;
  // Calibration key: largest per-channel rotation between keys 0-1 vs keys 1-2.
  if (opt.skip_calibration_key) {
    double j01 = 0, j12 = 0;
    double t1 = -1;
    for (size_t i = 0; i < c.rig.node.size(); ++i) {
      const aiNodeAnim* ch = c.rig.channel[i];
      if (!ch || ch->mNumRotationKeys < 3) continue;
      auto q = [&](int k) {
        const auto& v = ch->mRotationKeys[k].mValue;
        return Quat(v.w, v.x, v.y, v.z).normalized();
      };
      j01 = std::max(j01, q(0).angularDistance(q(1)));
      j12 = std::max(j12, q(1).angularDistance(q(2)));
      t1 = ch->mRotationKeys[1].mTime / c.tps;
    }
    if (t1 > 0 && j01 > 20 * M_PI / 180 && j01 > 5 * j12) c.t0 = t1;
  }
  c.duration = c.anim->mDuration / c.tps - c.t0;
  return c;
}

// Local transforms of every node at `seconds` into the clip.
std::vector<Trs> pose_at(const Clip& c, double seconds) {
  std::vector<Trs> L(c.rig.rest);
  for (size_t i = 0; i < c.rig.node.size(); ++i)
    if (c.rig.channel[i]) L[i] = sample(c.rig.channel[i], (c.t0 + seconds) * c.tps, c.rig.rest[i], c.rig.moved[i]);
  return L;
}

// The skeleton: every node below the top animated ancestor of the first animated node,
// parents first, at the pose of globals G (file units), with each one's index in the rig.
struct SkeletonNodes {
  std::vector<detail::SkelNode> nodes;
  std::vector<int> to_rig;
};

SkeletonNodes skeleton_nodes(const Rig& rig, const std::vector<Mat4>& G, const std::string& path) {
  const size_t nn = rig.node.size();
  int root = -1;
  for (size_t i = 0; i < nn && root < 0; ++i)
    if (rig.channel[i]) root = static_cast<int>(i);
  if (root < 0) gdsr::fail("load_body_sequence: " + path, "no animated node (no skeleton)");
  while (rig.parent[root] >= 0 && rig.channel[rig.parent[root]]) root = rig.parent[root];
  SkeletonNodes out;
  std::map<int, int> from_rig;
  for (size_t i = root; i < nn; ++i) {
    const int p = rig.parent[i];
    if (static_cast<int>(i) != root && !from_rig.count(p)) continue;
    from_rig[static_cast<int>(i)] = static_cast<int>(out.nodes.size());
    out.to_rig.push_back(static_cast<int>(i));
    detail::SkelNode sn;
    sn.name = rig.node[i]->mName.C_Str();
    sn.parent = static_cast<int>(i) == root ? -1 : from_rig[p];
    sn.pos = G[i].topRightCorner<3, 1>();
    out.nodes.push_back(sn);
  }
  return out;
}

// Turns each upper arm of the local transforms `pose` for which turn(arm direction) holds
// about its shoulder, to point sideways (away from the other shoulder) `below` radians under
// the horizontal. Rigs without two recognisable upper arms are left as they are.
void turn_upper_arms(const Rig& rig, std::vector<Trs>& pose, const std::string& path, double below,
                     const std::function<bool(const Vec3& arm)>& turn) {
  const std::vector<Mat4> G = rig.globals(pose);
  const SkeletonNodes sn = skeleton_nodes(rig, G, path);
  const std::vector<int> arms = detail::upper_arm_starts(sn.nodes);
  if (arms.size() != 2) return;
  const Vec3 mid = 0.5 * (sn.nodes[arms[0]].pos + sn.nodes[arms[1]].pos);
  for (int a : arms) {  // neither arm is the other's ancestor: G stays valid for both
    const Vec3 shoulder = sn.nodes[a].pos;
    int elbow = -1;  // the child farthest from the shoulder
    for (size_t k = 0; k < sn.nodes.size(); ++k)
      if (sn.nodes[k].parent == a &&
          (elbow < 0 || (sn.nodes[k].pos - shoulder).norm() > (sn.nodes[elbow].pos - shoulder).norm()))
        elbow = static_cast<int>(k);
    if (elbow < 0 || (sn.nodes[elbow].pos - shoulder).norm() < 1e-9) continue;
    const Vec3 arm = (sn.nodes[elbow].pos - shoulder).normalized();
    Vec3 side = shoulder - mid;
    side.y() = 0;
    if (!turn(arm) || side.norm() < 1e-9) continue;
    const Vec3 target = std::cos(below) * side.normalized() - std::sin(below) * Vec3::UnitY();
    // Global rotation Q about the shoulder: the local rotation becomes Rp^-1 Q Rp r.
    const Quat Q = Quat::FromTwoVectors(arm, target);
    const int r = sn.to_rig[a], par = rig.parent[r];
    const Mat4& Gp = par >= 0 ? G[par] : rig.pre;
    const Eigen::Matrix3d Rp = Gp.topLeftCorner<3, 3>();
    pose[r].r = Quat(Rp.inverse() * Q.toRotationMatrix() * Rp * pose[r].r.toRotationMatrix()).normalized();
  }
}

// A rest pose with the arms hanging down (the CMU 131 walks) would fuse the arms to the
// body's sides when it is built, and give garments a waist as wide as the elbows. Each upper
// arm more than 60 degrees below the horizontal is turned about its shoulder to point
// sideways, level: a T-pose. T- and A-poses are left exactly as they are.
void raise_hanging_arms(Rig& rig, const std::string& path) {
  turn_upper_arms(rig, rig.rest, path, 0, [](const Vec3& arm) { return arm.y() <= -std::sin(60 * M_PI / 180); });
}

// Metres per file unit of a skeleton body `height` tall (joint extent at its rest pose; the
// head and feet add 4%).
double skeleton_metres_per_unit(const std::vector<detail::SkelNode>& nodes, double height, const std::string& path) {
  double ymin = 1e300, ymax = -1e300;
  for (const auto& n : nodes) ymin = std::min(ymin, n.pos.y()), ymax = std::max(ymax, n.pos.y());
  if (!(ymax - ymin > 0)) gdsr::fail("load_body_sequence: " + path, "skeleton has zero height at the rest pose");
  return height / ((ymax - ymin) * 1.04);
}

// BodyOptions::min_shoulder_half_width. Returns the shoulder joints' distance from the middle as
// captured, metres (0: no two upper arms); `widened` says whether they were moved.
// Measured on 2026-12-07 over the salsa part of the 30 mm matrix (six garments on 60_02 and 61_03,
// 4 s from 2 s, frictions 0.3 and 0.30001: 24 runs), joints as filed -> moved out to 0.20 m:
// frames where the body crosses itself 2536 -> 780; runs free of self-intersections at both
// resolutions 21 -> 22 (worst 86.0% -> 94.9%); runs over the strain limits 5 -> 2; frames with
// cloth > 5 mm in the body outside pinches, LR / 2nd run, 36 / 30 -> 40 / 44, of which the
// t-shirt on 61_03 5 / 2 -> 24 / 25 (its cuff slides over the hand held forward, frames 57-67).
double widen_narrow_shoulders(Rig& rig, const BodyOptions& opt, const std::string& path, bool& widened) {
  widened = false;
  const std::vector<Mat4> G = rig.globals(rig.rest);
  const SkeletonNodes sn = skeleton_nodes(rig, G, path);
  const std::vector<int> arms = detail::upper_arm_starts(sn.nodes);
  if (arms.size() != 2 || sn.nodes.size() < 3) return 0;
  const double mpu = skeleton_metres_per_unit(sn.nodes, opt.height, path);
  const Vec3 mid = 0.5 * (sn.nodes[arms[0]].pos + sn.nodes[arms[1]].pos);
  Vec3 across = sn.nodes[arms[0]].pos - mid;
  across.y() = 0;
  const double half = across.norm() * mpu;
  if (!(half < opt.min_shoulder_half_width) || half < 1e-6) return half;
  for (int a : arms) {
    Vec3 out = sn.nodes[a].pos - mid;
    out.y() = 0;
    const int r = sn.to_rig[a], par = rig.parent[r];
    const Mat4& Gp = par >= 0 ? G[par] : rig.pre;
    const Vec3 local =
        Gp.topLeftCorner<3, 3>().inverse() * (out.normalized() * (opt.min_shoulder_half_width - half) / mpu);
    rig.rest[r].t += local;
    rig.moved[r] += local;
  }
  widened = true;
  return half;
}

// The body surface with its skin: the file's skinned meshes, or a body built around the
// skeleton (sb, and shape_to_rest: the skeleton body's landmark space -> rest pose).
struct Surface {
  Skin sk;
  detail::SkinnedBody sb;
  Mat4 shape_to_rest = Mat4::Identity();
};

Surface build_surface(const aiScene* s, const Clip& c, const std::vector<Mat4>& G_rest, const std::string& path,
                      const BodyOptions& opt) {
  Surface out;
  const Rig& rig = c.rig;
  if (c.skinned) {
    out.sk = skin_from_meshes(s, rig, path);
    weld(out.sk, out.sk.apply(G_rest));
    return out;
  }
  // The body is built at the file's rest pose with its own root translation, so the same
  // skeleton always gives the same mesh whatever start_seconds is.
  const std::vector<Mat4> G_shape = rig.globals(rig.rest);
  const SkeletonNodes sn = skeleton_nodes(rig, G_shape, path);
  const std::vector<detail::SkelNode>& nodes = sn.nodes;
  const std::vector<int>& to_rig = sn.to_rig;
  out.shape_to_rest = G_rest[to_rig[0]] * G_shape[to_rig[0]].inverse();
  if (nodes.size() < 3) gdsr::fail("load_body_sequence: " + path, "skeleton has fewer than 3 joints");
  const double mpu = skeleton_metres_per_unit(nodes, opt.height, path);
  out.sb = detail::build_skeleton_body(nodes, mpu, opt.body_edge);
  // Skin matrices: node k -> G(t) * G_rest^-1, bind space = rest world.
  Skin& sk = out.sk;
  sk.P = out.sb.V;
  sk.F = out.sb.F;
  sk.start = out.sb.skin_start;
  for (size_t k = 0; k < nodes.size(); ++k) {
    sk.mat_node.push_back(to_rig[k]);
    sk.mat_bind.push_back(G_shape[to_rig[k]].inverse());
  }
  sk.mat = out.sb.skin_node;
  sk.weight = out.sb.skin_weight;
  return out;
}

// Similarity from file units to metres: the rest pose stands on y = 0, centred in x and z.
struct ToMetres {
  double scale = 1;
  Vec3 shift = Vec3::Zero();
  Points3 operator()(const Points3& X) const { return (X.rowwise() - shift.transpose()) * scale; }
  Vec3 operator()(const Vec3& p) const { return (p - shift) * scale; }
};

ToMetres to_metres(const Points3& rest_raw, double height, double leg_extra, const std::string& path) {
  if (!rest_raw.allFinite()) gdsr::fail("load_body_sequence: " + path, "rest pose has non-finite vertices");
  const Vec3 lo = rest_raw.colwise().minCoeff(), hi = rest_raw.colwise().maxCoeff();
  if (!(hi.y() - lo.y() > 0)) gdsr::fail("load_body_sequence: " + path, "body has zero height at the rest pose");
  ToMetres m;
  // Skeleton bodies: standing height counts the legs as vertical (rest poses may spread them).
  m.scale = height / (hi.y() - lo.y() + leg_extra);
  m.shift = Vec3(0.5 * (lo.x() + hi.x()), lo.y(), 0.5 * (lo.z() + hi.z()));
  return m;
}

// Mirroring bind transforms flip triangles: make closed meshes enclose positive volume.
void orient_outward(Faces& F, const Points3& V) {
  double vol = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    vol += Vec3(V.row(F(f, 0))).dot(Vec3(V.row(F(f, 1))).cross(Vec3(V.row(F(f, 2)))));
  if (vol < 0) F.col(1).swap(F.col(2));
}

// Local transforms of every body frame: `blend` frames from the rest pose into the first
// motion pose (smoothstep), then n_motion frames of the clip at opt.fps from opt.start_seconds.
std::vector<std::vector<Trs>> frame_poses(const Clip& c, const std::vector<Trs>& rest_local,
                                          const std::vector<Trs>& first, int blend, int n_motion,
                                          const BodyOptions& opt) {
  const size_t nn = c.rig.node.size();
  std::vector<std::vector<Trs>> poses(blend + n_motion);
#pragma omp parallel for schedule(dynamic, 4)
  for (int f = 0; f < blend + n_motion; ++f) {
    if (f < blend) {
      const double a = smoothstep(static_cast<double>(f) / blend);
      std::vector<Trs> L = rest_local;
      for (size_t i = 0; i < nn; ++i) {
        L[i].t = (1 - a) * rest_local[i].t + a * first[i].t;
        L[i].r = rest_local[i].r.slerp(a, first[i].r);
        L[i].s = (1 - a) * rest_local[i].s + a * first[i].s;
      }
      poses[f] = std::move(L);
    } else {
      const int k = f - blend;
      poses[f] = k == 0 ? first : pose_at(c, opt.start_seconds + k / opt.fps);
    }
  }
  return poses;
}

// The body surface of every pose, metres. Frames are independent: parallel over frames
// (skinning one frame is too small to split).
std::vector<Points3> skin_frames(const Rig& rig, const Skin& sk, const ToMetres& to_out,
                                 const std::vector<std::vector<Trs>>& poses, const std::string& path) {
  std::vector<Points3> frames(poses.size());
  int bad_frame = -1;
#pragma omp parallel for schedule(dynamic, 4)
  for (int f = 0; f < static_cast<int>(poses.size()); ++f) {
    frames[f] = to_out(sk.apply(rig.globals(poses[f])));
    if (!frames[f].allFinite()) {
#pragma omp critical
      bad_frame = f;
    }
  }
  if (bad_frame >= 0)
    gdsr::fail("load_body_sequence: " + path, "non-finite vertices at frame " + std::to_string(bad_frame));
  return frames;
}

// The rig node of vertex i's heaviest skin influence.
int heaviest_node(const Skin& sk, Eigen::Index i) {
  int heaviest = sk.start[i];
  for (int k = sk.start[i] + 1; k < sk.start[i + 1]; ++k)
    if (sk.weight[k] > sk.weight[heaviest]) heaviest = k;
  return sk.mat_node[sk.mat[heaviest]];
}

// Per body vertex, the limb segment of its heaviest influence (detail::limb_segments; -1: the
// trunk, or a node outside the skeleton).
std::vector<int> vertex_segments(const Rig& rig, const Skin& sk, const std::string& path) {
  const SkeletonNodes sn = skeleton_nodes(rig, rig.globals(rig.rest), path);
  const std::vector<int> seg = detail::limb_segments(sn.nodes);
  std::vector<int> of_rig(rig.node.size(), -1);
  for (size_t k = 0; k < sn.nodes.size(); ++k) of_rig[sn.to_rig[k]] = seg[k];
  std::vector<int> out(sk.P.rows(), -1);
  for (Eigen::Index i = 0; i < sk.P.rows(); ++i) out[i] = of_rig[heaviest_node(sk, i)];
  return out;
}

// BodyOptions::yield_gap: every frame's overlaps given way (parallel over frames).
BodyYields yield_frames(const Faces& F, const Points3& rest, const std::vector<int>& segment, double gap,
                        std::vector<Points3>& frames) {
  BodyYields out;
  const int T = static_cast<int>(frames.size());
  out.max_move.assign(T, 0.0);
  std::vector<char> left(T, 0);
  BodyYieldOptions yo;
  yo.gap = gap;
#pragma omp parallel for schedule(dynamic, 1)
  for (int f = 0; f < T; ++f) {
    const BodyYield y = yield_self_overlap(F, frames[f], rest, segment, yo);
    out.max_move[f] = y.max_move;
    left[f] = y.buried_left > 0;
  }
  out.buried_left_frames = static_cast<int>(std::count(left.begin(), left.end(), 1));
  return out;
}

// Arm clearance (BodyOptions::arm_clearance). An arm is told from the rest of the body by
// skin: a vertex belongs to an arm when its heaviest influence is a node under that upper arm.
// Only arm vertices farther than kArmPartSeparation from the rest of the body at the build pose
// are checked (the upper arm joins the trunk at the shoulder).
// Tried on 2026-12-06, not kept: checking the upper arm near the shoulder too, against the faces
// that were not near it at the build pose (an upper arm swung into the back, CMU 131_01 frames
// 96-97 from 2 s). On 131_01 the body crossed itself in 31 frames instead of 33, and the 30 mm cloth
// stayed within the chaotic spread. On salsa 61_03 the armpit's own folds counted as inside: 37
// frames were still inside after a 30 degree turn (5 before), and the 30 mm t-shirt had LR / 2nd-run
// frames with cloth > 5 mm inside the body outside pinches 2 / 0 -> 10 / 7 (friction 0.3) and
// 2 / 0 -> 9 / 11 (0.30002), deepest 14.5 -> 19.6 mm and 10.0 -> 27.5 mm.
constexpr double kArmPartSeparation = 0.15;      // metres, as ValidityOptions::pinch_separation
constexpr double kArmTurnStep = 2 * M_PI / 180;  // search step; then 3 bisections (0.25 degrees)

struct ArmParts {
  std::vector<int> rig_node;               // the two upper arms' nodes (none: not recognised)
  std::vector<std::vector<int>> vertices;  // per arm: its vertices checked for clearance
  Faces others;                            // faces with no corner on an arm: trunk, legs, head
  std::vector<char> rim;                   // per face of `others`: a corner on its open rim (the shoulders)
};

bool under(const Rig& rig, int node, int ancestor) {
  for (; node >= 0; node = rig.parent[node])
    if (node == ancestor) return true;
  return false;
}

// rest: the body at the pose it was built in, metres.
ArmParts arm_parts(const Rig& rig, const Skin& sk, const Points3& rest, const std::string& path) {
  ArmParts parts;
  const SkeletonNodes sn = skeleton_nodes(rig, rig.globals(rig.rest), path);
  const std::vector<int> starts = detail::upper_arm_starts(sn.nodes);
  if (starts.size() != 2) return parts;
  for (int a : starts) parts.rig_node.push_back(sn.to_rig[a]);
  const Eigen::Index nv = sk.P.rows();
  std::vector<int> arm_of(nv, -1);
  for (Eigen::Index i = 0; i < nv; ++i)
    for (int a = 0; a < 2; ++a)
      if (under(rig, heaviest_node(sk, i), parts.rig_node[a])) arm_of[i] = a;
  std::vector<Eigen::Vector3i> others;
  for (Eigen::Index f = 0; f < sk.F.rows(); ++f)
    if (arm_of[sk.F(f, 0)] < 0 && arm_of[sk.F(f, 1)] < 0 && arm_of[sk.F(f, 2)] < 0)
      others.emplace_back(sk.F(f, 0), sk.F(f, 1), sk.F(f, 2));
  if (others.empty()) return ArmParts{};
  parts.others.resize(static_cast<Eigen::Index>(others.size()), 3);
  for (size_t f = 0; f < others.size(); ++f) parts.others.row(static_cast<Eigen::Index>(f)) = others[f].transpose();
  std::vector<char> on_rim(nv, 0);
  for (int v : boundary_vertices(parts.others)) on_rim[v] = 1;
  for (const Eigen::Vector3i& t : others) parts.rim.push_back(on_rim[t[0]] || on_rim[t[1]] || on_rim[t[2]]);
  const ClosestPoints cp = BodyQuery(TriMesh{rest, parts.others}).closest(rest, /*smooth_normals=*/false);
  parts.vertices.resize(2);
  for (Eigen::Index i = 0; i < nv; ++i)
    if (arm_of[i] >= 0 && std::abs(cp.sdist(i)) > kArmPartSeparation)
      parts.vertices[arm_of[i]].push_back(static_cast<int>(i));
  return parts;
}

// Arm a's point deepest towards the rest of the body in one frame V (metres): its signed
// distance from that surface (< 0 inside; +inf with nothing within 0.3 m), the point, and the
// surface's outward normal there. Points closest to the rim where the arms were cut off are
// left out: that surface is open, and the sign of a distance to its rim means nothing.
struct ArmGap {
  double gap = std::numeric_limits<double>::infinity();
  Vec3 point = Vec3::Zero(), normal = Vec3::Zero();
};

ArmGap arm_gap(const Points3& V, const ArmParts& parts, int a) {
  const std::vector<int>& vs = parts.vertices[a];
  Points3 Q(static_cast<Eigen::Index>(vs.size()), 3);
  for (size_t k = 0; k < vs.size(); ++k) Q.row(static_cast<Eigen::Index>(k)) = V.row(vs[k]);
  const ClosestPoints cp = BodyQuery(TriMesh{V, parts.others}).closest(Q, /*smooth_normals=*/false, 0.3);
  ArmGap g;
  for (Eigen::Index k = 0; k < Q.rows(); ++k)
    if (cp.face(k) >= 0 && !parts.rim[cp.face(k)] && cp.sdist(k) < g.gap) {
      g.gap = cp.sdist(k);
      g.point = Q.row(k).transpose();
      g.normal = cp.normal.row(k).transpose();
    }
  return g;
}

// Turns upper arm `node` of the local transforms L by `angle` radians about `axis` (unit, in
// the parent's frame) through its shoulder.
void turn_arm(std::vector<Trs>& L, int node, const Vec3& axis, double angle) {
  L[node].r = (Quat(Eigen::AngleAxisd(angle, axis)) * L[node].r).normalized();
}

struct ArmTurn {
  double angle = 0;          // radians
  Vec3 axis = Vec3::Zero();  // unit, in the upper arm's parent's frame
};

// The smallest turn of arm a about its shoulder in pose L that leaves opt.arm_clearance between
// the arm and the rest of the body, at most opt.max_arm_turn_degrees; about the axis that moves
// the arm's deepest point along the body's normal there. No turn when it is clear already.
// Some poses no turn clears: in the lunge of CMU 131_01 from 2 s (frames 44-53), trunk bent forward,
// the left forearm lies up to 59 mm deep in the lower back, and no turn up to 60 degrees clears it,
// about this axis, the upper arm's own axis or the axis across both, either way; nor does a turn
// of the forearm at the elbow (tried 2026-12-06): the deepest point is the elbow, 0.29 m below the
// shoulder, with the back bent over it. The tiered skirt's waistband knots there (`gdsr data
// preview --intersections --layer 1`; the validity figures count it as a knot begun where the body
// crosses itself).
ArmTurn arm_turn(const Rig& rig, const Skin& sk, const ToMetres& to_out, const ArmParts& parts, int a,
                 const std::vector<Trs>& L, const BodyOptions& opt) {
  auto gap = [&](const std::vector<Trs>& pose) { return arm_gap(to_out(sk.apply(rig.globals(pose))), parts, a); };
  const ArmGap g = gap(L);
  if (g.gap >= opt.arm_clearance) return {};
  const int r = parts.rig_node[a];
  const std::vector<Mat4> G = rig.globals(L);
  const Vec3 w = (g.point - to_out(Vec3(G[r].topRightCorner<3, 1>()))).cross(g.normal);
  if (w.norm() < 1e-9) return {};
  const Eigen::Matrix3d Rp = (rig.parent[r] >= 0 ? G[rig.parent[r]] : rig.pre).topLeftCorner<3, 3>();
  ArmTurn turn{0, (Rp.inverse() * w).normalized()};
  auto clear_at = [&](double angle) {
    std::vector<Trs> turned = L;
    turn_arm(turned, r, turn.axis, angle);
    return gap(turned).gap >= opt.arm_clearance;
  };
  const double max_angle = opt.max_arm_turn_degrees * M_PI / 180;
  double lo = 0, hi = -1;  // not clear at lo, clear at hi
  for (double t = kArmTurnStep; t < max_angle + kArmTurnStep && hi < 0; t += kArmTurnStep)
    (clear_at(std::min(t, max_angle)) ? hi : lo) = std::min(t, max_angle);
  if (hi < 0)
    hi = max_angle;
  else
    for (int k = 0; k < 3; ++k) {
      const double m = 0.5 * (lo + hi);
      (clear_at(m) ? hi : lo) = m;
    }
  turn.angle = hi;
  return turn;
}

// Turns the arms of every pose but the first (where garments are put on) that need it (see
// arm_turn), eased in and out: frame f gets the largest of the turns of frames g weighted by
// 1 - |f - g| / ease, so the turn changes by at most its size / ease per frame.
ArmTurns clear_arms(const Rig& rig, const Skin& sk, const ToMetres& to_out, const ArmParts& parts,
                    const BodyOptions& opt, std::vector<std::vector<Trs>>& poses) {
  const int T = static_cast<int>(poses.size());
  ArmTurns out;
  out.degrees.assign(T, 0.0);
  if (parts.rig_node.empty()) return out;
  std::vector<std::array<ArmTurn, 2>> need(T);
#pragma omp parallel for schedule(dynamic, 1)
  for (int f = 1; f < T; ++f)
    for (int a = 0; a < 2; ++a) need[f][a] = arm_turn(rig, sk, to_out, parts, a, poses[f], opt);
  const int ease = std::max(1, static_cast<int>(std::lround(opt.arm_turn_ease_seconds * opt.fps)));
  std::vector<char> turned(T, 0);
  for (int f = 1; f < T; ++f)
    for (int a = 0; a < 2; ++a) {
      ArmTurn eased;
      for (int g = std::max(1, f - ease + 1); g < std::min(T, f + ease); ++g) {
        const double angle = need[g][a].angle * (1 - std::abs(f - g) / static_cast<double>(ease));
        if (angle > eased.angle) eased = {angle, need[g][a].axis};
      }
      if (eased.angle <= 0) continue;
      turn_arm(poses[f], parts.rig_node[a], eased.axis, eased.angle);
      out.degrees[f] = std::max(out.degrees[f], eased.angle * 180 / M_PI);
      turned[f] = 1;
    }
  std::vector<char> inside(T, 0);
#pragma omp parallel for schedule(dynamic, 1)
  for (int f = 1; f < T; ++f)
    if (turned[f]) {
      const Points3 V = to_out(sk.apply(rig.globals(poses[f])));
      inside[f] = arm_gap(V, parts, 0).gap < 0 || arm_gap(V, parts, 1).gap < 0;
    }
  out.still_inside_frames = static_cast<int>(std::count(inside.begin(), inside.end(), 1));
  return out;
}

// Landmarks of the rest pose: hip, waist and chest sections, shoulder and crotch heights.
// Skeleton bodies know where their trunk is; skinned meshes use fixed fractions of the height.
BodyLandmarks measure_landmarks(const TriMesh& rest, const Surface& surf, const ToMetres& to_out, bool skinned,
                                double height) {
  BodyLandmarks lm;
  lm.height = height;
  const detail::SkinnedBody& sb = surf.sb;
  auto out_pt = [&](const Vec3& p) { return to_out(Vec3((surf.shape_to_rest * p.homogeneous()).head<3>())); };
  Vec3 hip_c, waist_c, chest_c;
  if (!skinned) {
    hip_c = out_pt(sb.hip_c), waist_c = out_pt(sb.waist_c), chest_c = out_pt(sb.chest_c);
    lm.shoulder_y = out_pt(Vec3(sb.chest_c.x(), sb.shoulder_y, sb.chest_c.z())).y();
  } else {
    const double H = height;
    hip_c = Vec3(0, 0.52 * H, 0), waist_c = Vec3(0, 0.61 * H, 0), chest_c = Vec3(0, 0.72 * H, 0);
    lm.shoulder_y = 0.82 * H;
  }
  try {
    lm.hips = measure_section(rest, hip_c.y(), hip_c.x(), hip_c.z());
    lm.waist = measure_section(rest, waist_c.y(), waist_c.x(), waist_c.z());
    lm.chest = measure_section(rest, chest_c.y(), chest_c.x(), chest_c.z());
  } catch (const std::exception&) {
    // Not a human-like shape (e.g. a test rig): leave the sections empty.
  }
  // Crotch: lowest crossing of the vertical line through the hip centre.
  lm.crotch_y = 0;
  const double x = hip_c.x(), z = hip_c.z();
  double best = 1e300;
  for (Eigen::Index f = 0; f < rest.F.rows(); ++f) {
    const Vec3 a = rest.V.row(rest.F(f, 0)), b = rest.V.row(rest.F(f, 1)), c = rest.V.row(rest.F(f, 2));
    // 2-D barycentrics in the xz plane
    const double d = (b.x() - a.x()) * (c.z() - a.z()) - (c.x() - a.x()) * (b.z() - a.z());
    if (std::abs(d) < 1e-18) continue;
    const double u = ((x - a.x()) * (c.z() - a.z()) - (c.x() - a.x()) * (z - a.z())) / d;
    const double v = ((b.x() - a.x()) * (z - a.z()) - (x - a.x()) * (b.z() - a.z())) / d;
    if (u < 0 || v < 0 || u + v > 1) continue;
    best = std::min(best, a.y() + u * (b.y() - a.y()) + v * (c.y() - a.y()));
  }
  if (best < 1e300) lm.crotch_y = best;
  return lm;
}

BodySequence load(const std::string& path, const BodyOptions& opt, bool rest_only) {
  if (!(opt.fps > 0) || !(opt.height > 0) || opt.rest_blend_frames < 0 || !(opt.start_seconds >= 0) ||
      !(opt.body_edge > 0) || !(opt.rest_arm_drop_degrees <= 80) || !(opt.arm_clearance >= 0) ||
      !(opt.max_arm_turn_degrees > 0 && opt.max_arm_turn_degrees <= 90) || !(opt.arm_turn_ease_seconds >= 0) ||
      !(opt.min_shoulder_half_width >= 0 && opt.min_shoulder_half_width < 0.5) ||
      !(opt.yield_gap >= 0 && opt.yield_gap < 0.05))
    gdsr::fail("load_body_sequence: " + path,
               "bad BodyOptions (fps, height, body_edge must be > 0, rest_blend_frames and start_seconds >= 0, "
               "rest_arm_drop_degrees <= 80, arm_clearance >= 0, max_arm_turn_degrees in (0, 90], "
               "arm_turn_ease_seconds >= 0, min_shoulder_half_width in [0, 0.5) m, yield_gap in [0, 0.05) m)");
  if (!std::ifstream(path).good()) gdsr::fail("load_body_sequence: " + path, "file not found or not readable");
  Assimp::Importer imp;
  const aiScene* s =
      imp.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_LimitBoneWeights);
  if (!s || !s->mRootNode)
    gdsr::fail("load_body_sequence: " + path, std::string("assimp cannot read it: ") + imp.GetErrorString());

  Clip clip = read_clip(s, path, opt);
  double captured_shoulder_half_width = 0;
  bool shoulders_widened = false;
  if (!clip.skinned) {
    raise_hanging_arms(clip.rig, path);
    captured_shoulder_half_width = widen_narrow_shoulders(clip.rig, opt, path, shoulders_widened);
  }
  if (opt.start_seconds > clip.duration)
    gdsr::fail("load_body_sequence: " + path,
               "start_seconds beyond the clip length " + std::to_string(clip.duration) + " s");
  double end = clip.duration;
  if (opt.max_seconds >= 0) end = std::min(end, opt.start_seconds + opt.max_seconds);
  const int n_motion = rest_only ? 1 : static_cast<int>(std::floor((end - opt.start_seconds) * opt.fps + 1e-9)) + 1;

  // Rest pose: the file's rest rotations with the first motion frame's translations.
  const std::vector<Trs> first = pose_at(clip, opt.start_seconds);
  std::vector<Trs> rest_local(clip.rig.rest);
  for (size_t i = 0; i < clip.rig.node.size(); ++i)
    if (clip.rig.channel[i]) rest_local[i].t = first[i].t;
  const std::vector<Mat4> G_rest = clip.rig.globals(rest_local);

  const Surface surf = build_surface(s, clip, G_rest, path, opt);
  const Points3 rest_raw = surf.sk.apply(G_rest);
  const ToMetres to_out = to_metres(rest_raw, opt.height, clip.skinned ? 0.0 : surf.sb.leg_extra, path);

  BodySequence seq;
  seq.F = surf.sk.F;
  orient_outward(seq.F, rest_raw);
  seq.fps = opt.fps;
  seq.source = path;
  seq.from_skeleton = !clip.skinned;
  seq.torso_found = clip.skinned || surf.sb.torso_found;
  seq.captured_shoulder_half_width = captured_shoulder_half_width;
  seq.shoulders_widened = shoulders_widened;
  // Frame 0, where garments are put on: the file's rest pose, or its A-pose (placed, scaled
  // and meshed as the file's rest pose, so every later frame is the same either way).
  std::vector<Trs> start_local = rest_local;
  if (opt.rest_arm_drop_degrees >= 0)
    turn_upper_arms(clip.rig, start_local, path, opt.rest_arm_drop_degrees * M_PI / 180,
                    [](const Vec3&) { return true; });
  seq.rest_V = opt.rest_arm_drop_degrees >= 0 ? to_out(surf.sk.apply(clip.rig.globals(start_local))) : to_out(rest_raw);
  seq.rest_blend_frames = rest_only ? 0 : opt.rest_blend_frames;
  if (!rest_only) {
    std::vector<std::vector<Trs>> poses = frame_poses(clip, start_local, first, opt.rest_blend_frames, n_motion, opt);
    if (opt.arm_clearance > 0) {
      const ArmParts parts = arm_parts(clip.rig, surf.sk, to_out(rest_raw), path);
      seq.arm_turns = clear_arms(clip.rig, surf.sk, to_out, parts, opt, poses);
    }
    seq.frames = skin_frames(clip.rig, surf.sk, to_out, poses, path);
    if (opt.yield_gap > 0) {
      seq.yields = yield_frames(seq.F, seq.rest_V, vertex_segments(clip.rig, surf.sk, path), opt.yield_gap, seq.frames);
      if (seq.rest_blend_frames > 0) seq.rest_V = seq.frames[0];  // the rest pose is frame 0
    }
  }
  seq.landmarks = measure_landmarks(TriMesh{seq.rest_V, seq.F}, surf, to_out, clip.skinned, opt.height);
  return seq;
}

}  // namespace

TriMesh BodySequence::frame_mesh(int t) const {
  if (t < 0 || t >= num_frames())
    gdsr::fail("BodySequence::frame_mesh",
               "frame " + std::to_string(t) + " out of range [0, " + std::to_string(num_frames()) + ") for " + source);
  return TriMesh{frames[t], F};
}

BodySequence load_body_sequence(const std::string& path, const BodyOptions& opt) { return load(path, opt, false); }

BodySection measure_section(const TriMesh& mesh, double y, double ax, double az, double max_radius) {
  std::vector<Vec2> pts;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int e = 0; e < 3; ++e) {
      const Vec3 a = mesh.V.row(mesh.F(f, e)), b = mesh.V.row(mesh.F(f, (e + 1) % 3));
      if ((a.y() - y) * (b.y() - y) > 0 || a.y() == b.y()) continue;
      const double s = (y - a.y()) / (b.y() - a.y());
      const Vec3 p = a + s * (b - a);
      if (std::hypot(p.x() - ax, p.z() - az) <= max_radius) pts.emplace_back(p.x(), p.z());
    }
  if (pts.size() < 3)
    gdsr::fail("measure_section", "plane y = " + std::to_string(y) + " misses the mesh near the axis");
  // Convex hull (monotone chain) for the circumference.
  std::sort(pts.begin(), pts.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Vec2> hull(2 * pts.size());
  size_t k = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], pts[i - 1]) <= 0) --k;
    hull[k++] = pts[i - 1];
  }
  hull.resize(k - 1);
  BodySection s;
  s.y = y;
  double x0 = 1e300, x1 = -1e300, z0 = 1e300, z1 = -1e300;
  for (const Vec2& p : pts)
    x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x()), z0 = std::min(z0, p.y()), z1 = std::max(z1, p.y());
  s.cx = 0.5 * (x0 + x1), s.cz = 0.5 * (z0 + z1);
  s.half_width = 0.5 * (x1 - x0), s.half_depth = 0.5 * (z1 - z0);
  for (size_t i = 0; i < hull.size(); ++i) s.circumference += (hull[(i + 1) % hull.size()] - hull[i]).norm();
  return s;
}

TriMesh load_body_rest(const std::string& path, const BodyOptions& opt, BodyLandmarks* landmarks) {
  BodySequence s = load(path, opt, true);
  if (landmarks) *landmarks = s.landmarks;
  return s.rest_mesh();
}

}  // namespace gdsr

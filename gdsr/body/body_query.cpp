#include "gdsr/body/body_query.hpp"

#include "gdsr/error.hpp"

#include "gdsr/geometry/triangle.hpp"

#include <embree3/rtcore.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace gdsr {
namespace {

RTCDevice shared_device() {
  static RTCDevice dev = [] {
    // One build thread: a BVH built by several threads differs from run to run and so did
    // the body features (measured: training steps not reproducible between processes, which
    // breaks an exact resume). Body meshes are small (a few thousand triangles); queries still
    // run in parallel under OpenMP.
    RTCDevice d = rtcNewDevice("threads=1");
    if (!d) gdsr::fail("BodyQuery", "cannot create an Embree device");
    return d;
  }();
  return dev;
}

}  // namespace

struct BodyQuery::Impl {
  TriMesh mesh;
  Update mode = Update::Rebuild;
  RTCScene scene = nullptr;
  RTCGeometry geom = nullptr;
  Points3 fn, vn;                                                // face / vertex normals (unit)
  Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> en;  // per face: 3 edge pseudonormals
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> adj;    // face across edge e (F(e)->F(e+1)), -1 none

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
  }

  void check_vertices(const Points3& V, const char* op) const {
    if (!V.allFinite()) {
      for (Eigen::Index i = 0; i < V.rows(); ++i)
        if (!V.row(i).allFinite())
          gdsr::fail(std::string("BodyQuery::") + op, "vertex " + std::to_string(i) + " is not finite");
    }
  }

  void upload() {
    auto* vb = static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    const Eigen::Index n = mesh.V.rows();
#pragma omp parallel for schedule(static) if (n > 50000)
    for (Eigen::Index i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) vb[3 * i + k] = static_cast<float>(mesh.V(i, k));
    rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geom);
    rtcCommitScene(scene);
    const RTCError err = rtcGetDeviceError(shared_device());
    if (err != RTC_ERROR_NONE) gdsr::fail("BodyQuery", "Embree error " + std::to_string(err) + " on commit");
    normals();
  }

  void normals() {
    const Eigen::Index nf = mesh.F.rows(), nv = mesh.V.rows();
    fn.resize(nf, 3);
    Points3 acc = Points3::Zero(nv, 3);
    // Bodies are small: threads only pay off for big meshes (and hurt on a loaded machine).
#pragma omp parallel for schedule(static) if (nf > 50000)
    for (Eigen::Index f = 0; f < nf; ++f) {
      const Vec3 a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
      const Vec3 n = (b - a).cross(c - a);
      const double l = n.norm();
      fn.row(f) = l > 0 ? Eigen::RowVector3d(n.transpose() / l) : Eigen::RowVector3d::Zero();
    }
    // Angle-weighted vertex normals (serial scatter; O(F)).
    for (Eigen::Index f = 0; f < nf; ++f) {
      const Vec3 n = fn.row(f);
      for (int k = 0; k < 3; ++k) {
        const Vec3 p = mesh.V.row(mesh.F(f, k));
        const Vec3 e1 = Vec3(mesh.V.row(mesh.F(f, (k + 1) % 3))) - p, e2 = Vec3(mesh.V.row(mesh.F(f, (k + 2) % 3))) - p;
        const double l1 = e1.norm(), l2 = e2.norm();
        if (!(l1 > 0 && l2 > 0)) continue;
        const double ang = std::acos(std::clamp(e1.dot(e2) / (l1 * l2), -1.0, 1.0));
        acc.row(mesh.F(f, k)) += ang * n.transpose();
      }
    }
    vn.resize(nv, 3);
#pragma omp parallel for schedule(static) if (nv > 50000)
    for (Eigen::Index i = 0; i < nv; ++i) {
      const double l = acc.row(i).norm();
      vn.row(i) = l > 0 ? Eigen::RowVector3d(acc.row(i) / l) : Eigen::RowVector3d::Zero();
    }
    en.resize(nf, 9);
#pragma omp parallel for schedule(static) if (nf > 50000)
    for (Eigen::Index f = 0; f < nf; ++f)
      for (int e = 0; e < 3; ++e) {
        Vec3 n = fn.row(f);
        if (adj(f, e) >= 0) n += Vec3(fn.row(adj(f, e)));
        const double l = n.norm();
        en.block<1, 3>(f, 3 * e) = l > 0 ? Eigen::RowVector3d(n.transpose() / l) : Eigen::RowVector3d::Zero();
      }
  }
};

BodyQuery::BodyQuery(const TriMesh& mesh, Update mode) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  if (mesh.V.rows() == 0 || mesh.F.rows() == 0)
    gdsr::fail("BodyQuery", "empty mesh (" + std::to_string(mesh.V.rows()) + " vertices, " +
                                std::to_string(mesh.F.rows()) + " faces)");
  if (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= mesh.V.rows())
    gdsr::fail("BodyQuery", "face index out of range [0, " + std::to_string(mesh.V.rows()) + ")");
  m.check_vertices(mesh.V, "BodyQuery");
  m.mesh = mesh;
  m.mode = mode;
  // Face adjacency across edges (for edge pseudonormals).
  const Eigen::Index nf = mesh.F.rows();
  m.adj.setConstant(nf, 3, -1);
  std::unordered_map<long long, int> dir;
  dir.reserve(3 * nf);
  const long long nv = mesh.V.rows();
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int e = 0; e < 3; ++e) dir[mesh.F(f, e) * nv + mesh.F(f, (e + 1) % 3)] = static_cast<int>(f);
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int e = 0; e < 3; ++e) {
      auto it = dir.find(mesh.F(f, (e + 1) % 3) * nv + mesh.F(f, e));
      if (it != dir.end()) m.adj(f, e) = it->second;
    }

  RTCDevice dev = shared_device();
  m.scene = rtcNewScene(dev);
  rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_LOW);
  m.geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(m.geom, mode == Update::Refit ? RTC_BUILD_QUALITY_REFIT : RTC_BUILD_QUALITY_LOW);
  rtcSetNewGeometryBuffer(m.geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.V.rows());
  auto* ib = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(m.geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nf));
  if (!ib) gdsr::fail("BodyQuery", "Embree cannot allocate buffers");
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ib[3 * f + k] = static_cast<unsigned>(mesh.F(f, k));
  rtcAttachGeometry(m.scene, m.geom);
  rtcReleaseGeometry(m.geom);  // the scene holds it
  m.upload();
}

BodyQuery::~BodyQuery() = default;
BodyQuery::BodyQuery(BodyQuery&&) noexcept = default;
BodyQuery& BodyQuery::operator=(BodyQuery&&) noexcept = default;

const TriMesh& BodyQuery::mesh() const { return impl_->mesh; }
const Points3& BodyQuery::face_normals() const { return impl_->fn; }
const Points3& BodyQuery::vertex_normals() const { return impl_->vn; }

void BodyQuery::update(const Points3& V) {
  Impl& m = *impl_;
  if (V.rows() != m.mesh.V.rows())
    gdsr::fail("BodyQuery::update",
               std::to_string(V.rows()) + " vertices, mesh has " + std::to_string(m.mesh.V.rows()));
  m.check_vertices(V, "update");
  m.mesh.V = V;
  m.upload();
}

namespace {
struct PQData {
  const BodyQuery* owner;
  const TriMesh* mesh;
  Vec3 q;
  double best_d2;
  int face, region;
  Vec3 cp;
  double u, v, w;
};

bool pq_callback(RTCPointQueryFunctionArguments* args) {
  auto* d = static_cast<PQData*>(args->userPtr);
  const unsigned f = args->primID;
  const TriMesh& M = *d->mesh;
  const Vec3 a = M.V.row(M.F(f, 0)), b = M.V.row(M.F(f, 1)), c = M.V.row(M.F(f, 2));
  const TriangleClosest t = closest_point_on_triangle(d->q, a, b, c);
  const Vec3& p = t.point;
  const double d2 = (p - d->q).squaredNorm();
  if (d2 < d->best_d2) {
    d->best_d2 = d2, d->face = static_cast<int>(f), d->region = static_cast<int>(t.region), d->cp = p;
    d->u = t.bary.x(), d->v = t.bary.y(), d->w = t.bary.z();
    // Conservative: Embree's bounds are float.
    args->query->radius = static_cast<float>(std::sqrt(d2) * (1 + 1e-5) + 1e-6);
    return true;
  }
  return false;
}
}  // namespace

ClosestPoints BodyQuery::closest(const Points3& Q, bool smooth_normals, double max_distance) const {
  const Impl& m = *impl_;
  const Eigen::Index n = Q.rows();
  if (!Q.allFinite())
    for (Eigen::Index i = 0; i < n; ++i)
      if (!Q.row(i).allFinite())
        gdsr::fail("BodyQuery::closest", "query point " + std::to_string(i) + " is not finite");
  if (!(max_distance > 0)) gdsr::fail("BodyQuery::closest", "max_distance must be > 0");
  ClosestPoints r;
  r.point.resize(n, 3);
  r.normal.resize(n, 3);
  r.sdist.resize(n);
  r.face.resize(n);
  r.bary.resize(n, 3);
  const double inf = std::numeric_limits<double>::infinity();
  const float r0 = std::isinf(max_distance) ? inf : static_cast<float>(max_distance);
#pragma omp parallel for schedule(dynamic, 64) if (n > 256)
  for (Eigen::Index i = 0; i < n; ++i) {
    PQData d{this, &m.mesh, Vec3(Q.row(i)), std::isinf(max_distance) ? inf : max_distance * max_distance,
             -1,   0,       Vec3::Zero(),   0,
             0,    0};
    RTCPointQuery pq;
    pq.x = static_cast<float>(d.q.x()), pq.y = static_cast<float>(d.q.y()), pq.z = static_cast<float>(d.q.z());
    pq.radius = r0;
    pq.time = 0.f;
    RTCPointQueryContext ctx;
    rtcInitPointQueryContext(&ctx);
    rtcPointQuery(m.scene, &pq, &ctx, pq_callback, &d);
    if (d.face < 0) {
      r.point.row(i) = Q.row(i);
      r.normal.row(i).setZero();
      r.sdist[i] = inf;
      r.face[i] = -1;
      r.bary.row(i).setZero();
      continue;
    }
    const int f = d.face;
    Vec3 pn;
    switch (d.region) {
      case 0:
        pn = m.fn.row(f);
        break;
      case 1:
      case 2:
      case 3:
        pn = m.vn.row(m.mesh.F(f, d.region - 1));
        break;
      case 4:
        pn = m.en.block<1, 3>(f, 0);
        break;
      case 5:
        pn = m.en.block<1, 3>(f, 3);
        break;
      default:
        pn = m.en.block<1, 3>(f, 6);
        break;
    }
    const Vec3 diff = d.q - d.cp;
    const double dist = std::sqrt(d.best_d2);
    r.point.row(i) = d.cp.transpose();
    r.sdist[i] = diff.dot(pn) < 0 ? -dist : dist;
    r.face[i] = f;
    r.bary.row(i) << d.u, d.v, d.w;
    if (smooth_normals) {
      Vec3 ns = d.u * Vec3(m.vn.row(m.mesh.F(f, 0))) + d.v * Vec3(m.vn.row(m.mesh.F(f, 1))) +
                d.w * Vec3(m.vn.row(m.mesh.F(f, 2)));
      const double l = ns.norm();
      r.normal.row(i) = (l > 0 ? Vec3(ns / l) : pn).transpose();
    } else {
      r.normal.row(i) = pn.transpose();
    }
  }
  return r;
}

namespace {
struct WithinData {
  const TriMesh* mesh;
  const std::function<bool(int)>* accept;
  Vec3 q;
  double r2;
  bool found;
};

bool within_callback(RTCPointQueryFunctionArguments* args) {
  auto* d = static_cast<WithinData*>(args->userPtr);
  const int f = static_cast<int>(args->primID);
  if (d->found || !(*d->accept)(f)) return false;
  const TriMesh& M = *d->mesh;
  const Vec3 a = M.V.row(M.F(f, 0)), b = M.V.row(M.F(f, 1)), c = M.V.row(M.F(f, 2));
  if ((closest_point_on_triangle(d->q, a, b, c).point - d->q).squaredNorm() > d->r2) return false;
  d->found = true;
  args->query->radius = 0.f;  // nothing more to look for
  return true;
}
}  // namespace

bool BodyQuery::any_face_within(const Vec3& q, double radius, const std::function<bool(int)>& accept) const {
  if (!q.allFinite()) gdsr::fail("BodyQuery::any_face_within", "query point is not finite");
  if (!(radius >= 0)) gdsr::fail("BodyQuery::any_face_within", "radius must be >= 0");
  WithinData d{&impl_->mesh, &accept, q, radius * radius, false};
  RTCPointQuery pq;
  pq.x = static_cast<float>(q.x()), pq.y = static_cast<float>(q.y()), pq.z = static_cast<float>(q.z());
  pq.radius = static_cast<float>(radius * (1 + 1e-5) + 1e-6);  // conservative: Embree's bounds are float
  pq.time = 0.f;
  RTCPointQueryContext ctx;
  rtcInitPointQueryContext(&ctx);
  rtcPointQuery(impl_->scene, &pq, &ctx, within_callback, &d);
  return d.found;
}

RayHits BodyQuery::intersect(const Points3& O, const Points3& D, double tmin, double tmax) const {
  const Impl& m = *impl_;
  const Eigen::Index n = O.rows();
  if (D.rows() != n)
    gdsr::fail("BodyQuery::intersect", std::to_string(n) + " origins but " + std::to_string(D.rows()) + " directions");
  if (!O.allFinite() || !D.allFinite()) gdsr::fail("BodyQuery::intersect", "non-finite origin or direction");
  if (!(tmin >= 0) || !(tmax >= tmin)) gdsr::fail("BodyQuery::intersect", "need 0 <= tmin <= tmax");
  RayHits r;
  r.t.resize(n);
  r.face.resize(n);
  r.uv.resize(n, 2);
  bool zero_dir = false;
  const float ftmax = std::isinf(tmax) ? std::numeric_limits<float>::infinity() : static_cast<float>(tmax);
#pragma omp parallel for schedule(dynamic, 256) if (n > 1024)
  for (Eigen::Index i = 0; i < n; ++i) {
    if (D.row(i).squaredNorm() == 0) {
      zero_dir = true;
      continue;
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = static_cast<float>(O(i, 0)), rh.ray.org_y = static_cast<float>(O(i, 1)),
    rh.ray.org_z = static_cast<float>(O(i, 2));
    rh.ray.dir_x = static_cast<float>(D(i, 0)), rh.ray.dir_y = static_cast<float>(D(i, 1)),
    rh.ray.dir_z = static_cast<float>(D(i, 2));
    rh.ray.tnear = static_cast<float>(tmin);
    rh.ray.tfar = ftmax;
    rh.ray.time = 0.f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m.scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
      r.t[i] = std::numeric_limits<double>::infinity();
      r.face[i] = -1;
      r.uv.row(i).setZero();
    } else {
      r.t[i] = rh.ray.tfar;
      r.face[i] = static_cast<int>(rh.hit.primID);
      r.uv.row(i) << rh.hit.u, rh.hit.v;
    }
  }
  if (zero_dir) gdsr::fail("BodyQuery::intersect", "zero ray direction");
  return r;
}

}  // namespace gdsr

#include "gdsr/sim/cloth_self_collision.hpp"

#include "gdsr/sim/contact_geometry.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/triangle.hpp"

#include <embree3/rtcore.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>

namespace sim {

using gdsr::Points3;
using gdsr::Vec3;

namespace {

[[noreturn]] void fail(const std::string& msg) { gdsr::fail("sim/cloth_self_collision", msg); }

// Sorts pairs by (key0, key1) and drops repeats: a counting sort on key0 in [0, n) (linear in
// the pair count; std::sort of the 100k-400k pairs of an HR detection took a third of it), then
// each bucket by key1. Same order as sorting by the pair of keys.
template <class P, class Key0, class Key1>
void sort_unique_pairs(std::vector<P>& v, int n, Key0 key0, Key1 key1) {
  std::vector<int> start(static_cast<size_t>(n) + 1, 0);
  for (const P& p : v) ++start[key0(p) + 1];
  for (int i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<P> out(v.size());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (const P& p : v) out[fill[key0(p)]++] = p;
  size_t kept = 0;
  for (int i = 0; i < n; ++i) {
    const auto b = out.begin() + start[i], e = out.begin() + start[i + 1];
    std::sort(b, e, [&](const P& x, const P& y) { return key1(x) < key1(y); });
    for (auto it = b; it != e; ++it)
      if (it == b || key1(*it) != key1(*(it - 1))) out[kept++] = *it;
  }
  out.resize(kept);
  v.swap(out);
}

// Squared distance between the boxes [lo1, hi1] and [lo2, hi2]: a lower bound of the
// squared distance between anything inside them, to skip the exact test for pairs clearly
// too far apart (HR skirt on CMU 61_02: 1.03 -> 0.92 s per frame, output unchanged).
// kGapMargin keeps rounding from skipping a pair the exact test would keep.
double box_gap2(const Vec3& lo1, const Vec3& hi1, const Vec3& lo2, const Vec3& hi2) {
  double g2 = 0;
  for (int c = 0; c < 3; ++c) {
    const double g = std::max({0.0, lo2[c] - hi1[c], lo1[c] - hi2[c]});
    g2 += g * g;
  }
  return g2;
}
constexpr double kGapMargin = 1 + 1e-9;

// Uncontended in practice (Embree's device runs one thread per call): an atomic flag.
class SpinLock {
 public:
  void lock() {
    while (flag_.test_and_set(std::memory_order_acquire)) {
    }
  }
  void unlock() { flag_.clear(std::memory_order_release); }

 private:
  std::atomic_flag flag_ = ATOMIC_FLAG_INIT;
};

}  // namespace

// Embree device, the per-detection vertex boxes the bounds callbacks read and the collected
// pairs. Three primitive sets, each a user geometry in its own scene: vertices, edges and faces,
// each bounded by its vertices' path boxes (vertex_boxes).
struct SelfCollision::Embree {
  RTCDevice device = nullptr;
  Vec3 detect_frame_motion = Vec3::Zero();  // the boxes frame's motion at the last detect (redetect continues it)
  const SelfCollision* owner = nullptr;
  // Per kind (vertices, edges, faces): each primitive's box in the last scene built of it,
  // written by the bounds callbacks, beside its vertex ids (one, two or three; -1 for none), so
  // the callback reads one record per side of each pair Embree reports.
  struct Prim {
    RTCBounds box;
    int v[3];
  };
  mutable std::vector<Prim> prims[3];
  // The primitives a scene holds, of one kind (0 vertices, 1 edges, 2 faces): full ids
  // first + primID, or ids[primID] if ids is set. Read by prim_bounds whenever the scene is
  // committed (built or refitted): a kept scene reads its copy in kept_lists.
  struct PrimList {
    const Embree* e;
    int kind;
    int first = 0;
    const int* ids = nullptr;
  };
  // The scenes of the last detect (vertices, faces, then the edge chunks), kept for redetect:
  // their boxes still bound the paths of every primitive no vertex of which has moved since.
  // The next detect refits them unless it rebuilds: on 1.5 s of the HR t-shirt on salsa 60_02
  // (872 detections) building took 14 of 95 s; refitting all but the first of each frame, 4.6 s
  // (refitting all along saved 0.9 s more but made the collides 4% slower, 1.6 s).
  static constexpr int kEdgeChunks = 8;
  RTCScene kept[2 + kEdgeChunks] = {};
  int chunk_first[kEdgeChunks + 1] = {};  // edge chunk c holds edges [chunk_first[c], chunk_first[c + 1])
  PrimList kept_lists[2 + kEdgeChunks];   // what each kept scene holds (read again by a refit)
  // Kept scene k, of `count` primitives of `list`: its tree refitted to the primitives' new
  // boxes if it exists and `rebuild` is false (same pairs: the callback tests each pair's own
  // boxes), else built anew. A refit keeps the count: it is fixed by the faces, which a
  // SelfCollision never changes.
  void keep_scene(int k, int count, const PrimList& list, bool rebuild) {
    RTCScene& sc = kept[k];
    kept_lists[k] = list;
    if (sc && !rebuild) {
      rtcCommitGeometry(rtcGetGeometry(sc, 0));
      rtcCommitScene(sc);
      return;
    }
    if (sc) rtcReleaseScene(sc);
    sc = scene(count, kept_lists[k], true);
  }
  void release_kept() {
    for (RTCScene& sc : kept)
      if (sc) rtcReleaseScene(sc), sc = nullptr;
  }
  ~Embree() {
    release_kept();
    if (device) rtcReleaseDevice(device);
  }
  // Each vertex's path box as floats rounded outwards (lower x, y, z, upper x, y, z), set by
  // vertex_boxes before the scenes are built or refitted: a primitive's box is the union of its
  // vertices' (rounding is monotonic, so the union of the rounded boxes is the rounded union, bit
  // for bit). Taken per primitive, the trees' builds and refits took 8.5 s of CPU over 0.5 s of
  // the HR and LR t-shirt on salsa 60_02, now 5.6 s.
  std::vector<std::array<float, 6>> vertex_box;
  // The path x + a motion, a in [0, 1] (motion null: x alone), grown by pad, is boxed in a frame
  // that moves along with the cloth: as x - frame_start + a (motion - frame_motion). The same
  // shift for every primitive leaves each pair's relative motion as it was, so the test stays
  // conservative, but the boxes of cloth carried along by a limb or the turning body stay short.
  void vertex_boxes(const Points3& x, const Points3* motion, double pad, const Vec3& frame_start,
                    const Vec3& frame_motion) {
    vertex_box.resize(x.rows());
    for (long v = 0; v < x.rows(); ++v)
      for (int c = 0; c < 3; ++c) {
        const double a = x(v, c) - frame_start[c];
        const double b = motion ? a + (*motion)(v, c) - frame_motion[c] : a;
        vertex_box[v][c] = std::nextafter(static_cast<float>(std::min(a, b) - pad), -1e30f);
        vertex_box[v][3 + c] = std::nextafter(static_cast<float>(std::max(a, b) + pad), 1e30f);
      }
  }
  // Box of the paths of vertices ids[0..n).
  void bounds(const int* ids, int n, RTCBounds* o) const {
    std::array<float, 6> b = vertex_box[ids[0]];
    for (int k = 1; k < n; ++k)
      for (int c = 0; c < 3; ++c) {
        b[c] = std::min(b[c], vertex_box[ids[k]][c]);
        b[3 + c] = std::max(b[3 + c], vertex_box[ids[k]][3 + c]);
      }
    *o = RTCBounds{b[0], b[1], b[2], 0, b[3], b[4], b[5], 0};
  }
  // Bounds callback of every scene: the primitive's path box, also stored in prims.
  static void prim_bounds(const RTCBoundsFunctionArguments* a) {
    const auto* l = static_cast<const PrimList*>(a->geometryUserPtr);
    const SelfCollision& sc = *l->e->owner;
    const int id = l->ids ? l->ids[a->primID] : l->first + static_cast<int>(a->primID);
    int v[3] = {id, -1, -1}, n = 1;
    if (l->kind == 1) v[0] = sc.edges_[id][0], v[1] = sc.edges_[id][1], n = 2;
    if (l->kind == 2) v[0] = sc.F_(id, 0), v[1] = sc.F_(id, 1), v[2] = sc.F_(id, 2), n = 3;
    l->e->bounds(v, n, a->bounds_o);
    l->e->prims[l->kind][id] = {*a->bounds_o, {v[0], v[1], v[2]}};
  }
  RTCScene scene(int count, const PrimList& list, bool refittable = false) {
    RTCScene sc = rtcNewScene(device);
    rtcSetSceneBuildQuality(sc, RTC_BUILD_QUALITY_LOW);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    if (refittable) {  // both are needed: with the geometry's REFIT alone a commit still rebuilt
      rtcSetSceneFlags(sc, RTC_SCENE_FLAG_DYNAMIC);
      rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_REFIT);
    }
    rtcSetGeometryUserPrimitiveCount(geom, static_cast<unsigned>(count));
    rtcSetGeometryUserData(geom, const_cast<PrimList*>(&list));
    rtcSetGeometryBoundsFunction(geom, prim_bounds, nullptr);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(sc, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(sc);
    return sc;
  }
  // Pairs of primitives (primID0, primID1) of two scenes of the given kinds (0 vertices,
  // 1 edges, 2 faces) whose boxes overlap and which share no vertex, each unordered pair
  // once, given to the narrow phase as soon as Embree reports them, so the many pairs it
  // rejects are never stored (storing them and reading them back was a fifth of a detection).
  // Two collides may run at once (each has its own Overlaps).
  // One side of a collide: which primitives its scene holds, and which pairs to leave out.
  struct Side {
    int first = 0;               // full id of the scene's primitive 0 (edge scenes of a range of edges) ...
    const int* ids = nullptr;    // ... or, if set, the full id of each of its primitives (redetect's scenes)
    const char* skip = nullptr;  // if set, per full id: pairs with this primitive are left out
  };
  template <class Out> struct Overlaps {
    const SelfCollision* sc;
    Side side0, side1;
    bool self;              // both scenes are the same one: keep p < q only
    const Prim* prim0;      // all primitives of the two kinds (Embree::prims), by full id
    const Prim* prim1;
    const Narrow* narrow;
    SpinLock mutex;  // in case Embree calls back from several threads (a pthread mutex was 4% of a simulation)
    std::vector<Out> kept;
  };
  // The callback, specialised on the vertex counts of the two kinds: it runs for every box
  // overlap. Embree also reports some pairs of a BVH leaf whose own boxes do not overlap
  // (which ones depends on the BVH); they are dropped here, so the pairs found do not depend
  // on how the primitives are split into scenes.
  // Mapped: a side has ids or skip (redetect's collides).
  template <int N0, int N1, class Out, bool Mapped> static void gather(void* user, RTCCollision* c, unsigned int n) {
    auto* o = static_cast<Overlaps<Out>*>(user);
    Out keep[64];
    int nk = 0;
    for (unsigned k = 0; k < n; ++k) {
      int p = static_cast<int>(c[k].primID0), q = static_cast<int>(c[k].primID1);
      if (o->self && p >= q) continue;
      if (Mapped) {
        p = o->side0.ids ? o->side0.ids[p] : p + o->side0.first;
        q = o->side1.ids ? o->side1.ids[q] : q + o->side1.first;
        if ((o->side0.skip && o->side0.skip[p]) || (o->side1.skip && o->side1.skip[q])) continue;
        if (N0 == 2 && N1 == 2 && p > q) std::swap(p, q);  // an edge-edge pair is (a < b)
      } else {
        p += o->side0.first;
        q += o->side1.first;
      }
      const Prim& pa = o->prim0[p];
      const Prim& pb = o->prim1[q];
      bool adjacent = false;
      for (int i = 0; i < N0; ++i)
        for (int j = 0; j < N1; ++j) adjacent |= pa.v[i] == pb.v[j];
      if (adjacent) continue;
      const RTCBounds& ba = pa.box;
      const RTCBounds& bb = pb.box;
      if (ba.lower_x > bb.upper_x || bb.lower_x > ba.upper_x || ba.lower_y > bb.upper_y || bb.lower_y > ba.upper_y ||
          ba.lower_z > bb.upper_z || bb.lower_z > ba.upper_z)
        continue;
      if (!o->sc->narrow_phase(*o->narrow, p, q, keep[nk])) continue;
      if (++nk == 64) {
        std::lock_guard<SpinLock> lock(o->mutex);
        o->kept.insert(o->kept.end(), keep, keep + nk);
        nk = 0;
      }
    }
    std::lock_guard<SpinLock> lock(o->mutex);
    o->kept.insert(o->kept.end(), keep, keep + nk);
  }
  // Pairs kept by the last collide of each call site (slot): the next one reserves that
  // many, as growing the list was 2.5% of a simulation.
  // Slots: vertex-face, the pairs of edge chunks, redetect's collides, the tangle test's two.
  static constexpr int kRedetectSlot = 1 + kEdgeChunks * (kEdgeChunks + 1) / 2;
  static constexpr int kSlots = kRedetectSlot + 4 + kEdgeChunks + 2;
  size_t last_count[kSlots] = {};
  // The narrow phase's survivors among the overlaps of scenes a (kind ka) and b (kind kb), in
  // callback order (the caller sorts them). Out: VT (vertices x faces), EE (edges x edges) or
  // (edge, face) crossings (std::array<int, 2>).
  template <class Out>
  std::vector<Out> collide(RTCScene a, int ka, Side sa, RTCScene b, int kb, Side sb, int slot, const Narrow& narrow) {
    if ((ka != 1 && sa.first != 0) || (kb != 1 && sb.first != 0)) fail("only edge scenes hold a range");
    Overlaps<Out> o{owner, sa, sb, a == b, prims[ka].data(), prims[kb].data(), &narrow, {}, {}};
    size_t& last = last_count[slot];
    o.kept.reserve(last + last / 8);
    const bool mapped = sa.ids || sb.ids || sa.skip || sb.skip;
    RTCCollideFunc fn = nullptr;
    if (ka == 0 && kb == 2) fn = mapped ? gather<1, 3, Out, true> : gather<1, 3, Out, false>;
    if (ka == 1 && kb == 1) fn = mapped ? gather<2, 2, Out, true> : gather<2, 2, Out, false>;
    if (ka == 1 && kb == 2) fn = mapped ? gather<2, 3, Out, true> : gather<2, 3, Out, false>;
    if (!fn) fail("no collide callback for these primitive kinds");
    rtcCollide(a, b, fn, &o);
    const RTCError err = rtcGetDeviceError(device);
    if (err != RTC_ERROR_NONE) fail("Embree collide failed (error " + std::to_string(static_cast<int>(err)) + ")");
    last = o.kept.size();
    return std::move(o.kept);
  }
};

namespace {
// Runs job(0) .. job(n - 1) on two threads, each job taken by the first thread free (the
// largest first, if the caller lists them so); on one when OpenMP is limited to one (ctest runs
// two tests side by side with OMP_NUM_THREADS=1, and two threads each spin-waited for a core:
// the kneel test took 148 s in CI, 35 s alone on one thread); rethrows the first exception a job threw.
template <class Job> void run_jobs(int n, Job&& job) {
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic, 1) num_threads(2) if (omp_get_max_threads() > 1)
  for (int k = 0; k < n; ++k) {
    try {
      job(k);
    } catch (...) {
#pragma omp critical(self_collision_error)
      error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

struct ScenesGuard {  // releases the scenes of one broad phase, also when a collide throws
  RTCScene s[16] = {};
  ~ScenesGuard() {
    for (RTCScene sc : s)
      if (sc) rtcReleaseScene(sc);
  }
};
}  // namespace

SelfCollision::SelfCollision(const gdsr::Faces& F, int num_vertices) : F_(F), embree_(std::make_unique<Embree>()) {
  if (F.rows() > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= num_vertices)) fail("faces index missing vertices");
  std::map<std::pair<int, int>, int> ids;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = F(f, k), j = F(f, (k + 1) % 3);
      const auto key = std::make_pair(std::min(i, j), std::max(i, j));
      const auto [it, added] = ids.emplace(key, static_cast<int>(edges_.size()));
      if (added) {
        edges_.push_back({key.first, key.second});
        edge_faces_.push_back({f, -1});
      } else {
        edge_faces_[it->second][1] = f;
      }
    }
  tangled_.assign(num_vertices, 0);
  vertex_faces_ = gdsr::vertex_faces(F, num_vertices);
  vertex_edges_ = gdsr::vertex_edges(edges_, num_vertices);
  // One broad-phase thread: Embree's own (TBB) threads beside the narrow phase's OpenMP ones
  // made 2-thread runs slower (1.09 against 0.93 s per HR frame on 0.3 s of CMU 01_01).
  embree_->device = rtcNewDevice("threads=1");
  if (!embree_->device) fail("cannot create an Embree device");
}

SelfCollision::~SelfCollision() = default;

int SelfCollision::num_tangled_vertices() const {
  return static_cast<int>(std::count(tangled_.begin(), tangled_.end(), 1));
}

void SelfCollision::detect(const Points3& x, const Points3& motion, double slack, double thickness, bool tangle_test) {
  const int nf = static_cast<int>(F_.rows()), nv = static_cast<int>(x.rows()), ne = static_cast<int>(edges_.size());
  if (motion.rows() != x.rows() || static_cast<int>(tangled_.size()) != x.rows())
    fail("positions or motion do not match the vertex count");
  if (!(slack >= 0) || !(thickness > 0)) fail("slack must be >= 0 and thickness > 0");
  vt_.clear();
  ee_.clear();
  if (tangle_test) {
    std::fill(tangled_.begin(), tangled_.end(), 0);
    intersecting_ = 0;
    crossings_.clear();
  }
  if (nf < 2) return;
  ++detections_;

  // Broad phase: vertex, edge and face path boxes (Embree BVHs), collided pairwise.
  auto& E = *embree_;
  const double pad = 0.5 * thickness + slack;
  E.owner = this;
  E.prims[0].resize(nv);
  E.prims[1].resize(ne);
  E.prims[2].resize(nf);
  constexpr int K = Embree::kEdgeChunks;
  int* first = E.chunk_first;
  for (int c = 0; c <= K; ++c) first[c] = static_cast<int>(static_cast<long long>(ne) * c / K);
  // The edges are collided with each other in K scenes of consecutive edges (chunks), so that
  // the pairs of chunks (and the vertex-face pairs) are jobs the two threads can share out.
  const Embree::PrimList vertices{&E, 0}, faces{&E, 2};
  Embree::PrimList chunks[K];
  for (int c = 0; c < K; ++c) chunks[c] = {&E, 1, first[c]};
  // The narrow phase runs inside the collides' callbacks, each pair on its own, so what is
  // kept does not depend on which thread found it; the kept pairs are sorted afterwards.
  const Narrow narrow{&x, &motion, slack, thickness};
  if (tangle_test) {
    // An edge crossing a face now: tight boxes of the current positions (the swept, padded
    // boxes below would pass several times more candidates for the same exact test). First,
    // so that the edge and face boxes left in E.prims are the swept ones redetect relies on.
    E.vertex_boxes(x, nullptr, 0, Vec3::Zero(), Vec3::Zero());
    // Two halves of the edges against the faces, on two threads.
    ScenesGuard g;  // s[0], s[1]: the halves of the edges; s[2]: the faces
    const int half = ne / 2;
    const Embree::PrimList halves[2] = {{&E, 1, 0}, {&E, 1, half}};
    run_jobs(3, [&](int k) { g.s[k] = k < 2 ? E.scene(k ? ne - half : half, halves[k]) : E.scene(nf, faces); });
    std::vector<std::array<int, 2>> parts[2];
    run_jobs(2, [&](int k) {
      if ((k ? ne - half : half) > 0)  // (Embree's collide crashed on an empty scene)
        parts[k] =
            E.collide<std::array<int, 2>>(g.s[k], 1, {k ? half : 0}, g.s[2], 2, {}, Embree::kSlots - 2 + k, narrow);
    });
    crossings_ = std::move(parts[0]);
    crossings_.insert(crossings_.end(), parts[1].begin(), parts[1].end());
    std::sort(crossings_.begin(), crossings_.end());  // the broad phase's order is not fixed
    intersecting_ = static_cast<int>(crossings_.size());
    for (const auto& [e, f] : crossings_) {
      tangled_[edges_[e][0]] = tangled_[edges_[e][1]] = 1;
      for (int i = 0; i < 3; ++i) tangled_[F_(f, i)] = 1;
    }
  }
  E.detect_frame_motion = motion.colwise().mean().transpose();  // (nf >= 2: motion has rows)
  E.vertex_boxes(x, &motion, pad, Vec3::Zero(), E.detect_frame_motion);
  {
    // Vertex-face and edge-edge pairs on two threads (Embree's device runs one thread per
    // call), as jobs taken in turn: the vertex-face pairs, then every pair of edge chunks
    // (each unordered pair of edges once, as one scene collided with itself would give them),
    // the largest jobs first: each chunk with itself (edges of near ids are near each other: on
    // the t-shirt on salsa 60_02 these hold 80% of the edge-edge pairs kept, 7.7x the work of all the
    // pairs of two chunks) before the pairs of chunks, so that neither thread waits long for the
    // other's last job (the other way round, the jobs' CPU time was 0.93 of twice their wall
    // time, now 0.98: 3% less wall time in the collides).
    RTCScene* sc = E.kept;  // [0] vertices, [1] faces, [2 + c] edge chunk c; kept for redetect
    run_jobs(2 + K, [&](int k) {
      if (k == 0)
        E.keep_scene(0, nv, vertices, tangle_test);
      else if (k == 1)
        E.keep_scene(1, nf, faces, tangle_test);
      else
        E.keep_scene(k, first[k - 1] - first[k - 2], chunks[k - 2], tangle_test);
    });
    std::vector<std::array<int, 2>> jobs = {{-1, -1}};             // (-1, -1): vertex-face; (c, d): edge chunks c <= d
    auto empty = [&](int c) { return first[c + 1] == first[c]; };  // (Embree's collide crashed on an empty scene)
    for (int c = 0; c < K; ++c)
      if (!empty(c)) jobs.push_back({c, c});
    for (int c = 0; c < K; ++c)
      for (int d = c + 1; d < K; ++d)
        if (!empty(c) && !empty(d)) jobs.push_back({c, d});
    const int njobs = static_cast<int>(jobs.size());
    std::vector<std::vector<EE>> ee_parts(jobs.size());
    run_jobs(njobs, [&](int k) {
      const auto [c, d] = jobs[k];
      if (c < 0)
        vt_ = E.collide<VT>(sc[0], 0, {}, sc[1], 2, {}, 0, narrow);
      else
        ee_parts[k] = E.collide<EE>(sc[2 + c], 1, {first[c]}, sc[2 + d], 1, {first[d]}, k, narrow);
    });
    size_t total = 0;
    for (const auto& part : ee_parts) total += part.size();
    ee_.reserve(total);
    for (const auto& part : ee_parts) ee_.insert(ee_.end(), part.begin(), part.end());
  }
  sort_pairs();
}

void SelfCollision::redetect(const Points3& x, const Points3& start, const Points3& motion,
                             const std::vector<char>& moved, double elapsed, double slack, double thickness) {
  const int nf = static_cast<int>(F_.rows()), nv = static_cast<int>(x.rows()), ne = static_cast<int>(edges_.size());
  if (start.rows() != nv || motion.rows() != nv || static_cast<int>(moved.size()) != nv ||
      static_cast<int>(tangled_.size()) != nv)
    fail("positions, paths or moved flags do not match the vertex count");
  if (!(slack >= 0) || !(thickness > 0)) fail("slack must be >= 0 and thickness > 0");
  if (!(elapsed >= 0 && elapsed <= 1)) fail("elapsed must be in [0, 1]");
  if (nf < 2) return;
  auto& E = *embree_;
  if (!E.kept[0]) fail("redetect needs a detect first");
  // The moved primitives: ids[0] vertices, ids[1] edges, ids[2] faces with a moved vertex.
  std::vector<int> ids[3];
  std::vector<char> moved_e(ne, 0), moved_f(nf, 0);
  for (int v = 0; v < nv; ++v)
    if (moved[v]) ids[0].push_back(v);
  if (ids[0].empty()) return;
  for (int e = 0; e < ne; ++e)
    if (moved[edges_[e][0]] || moved[edges_[e][1]]) ids[1].push_back(e), moved_e[e] = 1;
  for (int f = 0; f < nf; ++f)
    if (moved[F_(f, 0)] || moved[F_(f, 1)] || moved[F_(f, 2)]) ids[2].push_back(f), moved_f[f] = 1;
  ++redetections_;
  vt_.erase(std::remove_if(vt_.begin(), vt_.end(), [&](const VT& c) { return moved[c.v] || moved_f[c.f]; }), vt_.end());
  ee_.erase(std::remove_if(ee_.begin(), ee_.end(), [&](const EE& c) { return moved_e[c.a] || moved_e[c.b]; }),
            ee_.end());

  E.owner = this;
  E.vertex_boxes(start, &motion, 0.5 * thickness + slack, elapsed * E.detect_frame_motion,
                 (1 - elapsed) * E.detect_frame_motion);
  const Embree::PrimList lists[3] = {{&E, 0, 0, ids[0].data()}, {&E, 1, 0, ids[1].data()}, {&E, 2, 0, ids[2].data()}};
  ScenesGuard g;  // s[k]: the moved primitives of kind k
  run_jobs(3, [&](int k) {
    if (!ids[k].empty()) g.s[k] = E.scene(static_cast<int>(ids[k].size()), lists[k]);
  });
  // Each pair with a moved primitive once: moved x unmoved (the unmoved side in detect's
  // scenes, its moved primitives skipped there), moved x moved.
  constexpr int K = Embree::kEdgeChunks;
  const Narrow narrow{&start, &motion, slack, thickness, &x};
  using Side = Embree::Side;
  const Side mv{0, ids[0].data()}, me{0, ids[1].data()}, mf{0, ids[2].data()};
  std::vector<VT> vt_parts[3];
  std::vector<EE> ee_parts[1 + K];
  run_jobs(4 + K, [&](int k) {
    const int slot = Embree::kRedetectSlot + k;
    if (k == 0)
      vt_parts[0] = E.collide<VT>(g.s[0], 0, mv, E.kept[1], 2, {0, nullptr, moved_f.data()}, slot, narrow);
    else if (k == 1 && g.s[2])
      vt_parts[1] = E.collide<VT>(E.kept[0], 0, {0, nullptr, moved.data()}, g.s[2], 2, mf, slot, narrow);
    else if (k == 2 && g.s[2])
      vt_parts[2] = E.collide<VT>(g.s[0], 0, mv, g.s[2], 2, mf, slot, narrow);
    else if (k == 3 && g.s[1])
      ee_parts[0] = E.collide<EE>(g.s[1], 1, me, g.s[1], 1, me, slot, narrow);
    else if (k >= 4 && g.s[1] && E.chunk_first[k - 3] > E.chunk_first[k - 4])  // (collide crashed on an empty scene)
      ee_parts[k - 3] = E.collide<EE>(g.s[1], 1, me, E.kept[2 + k - 4], 1,
                                      {E.chunk_first[k - 4], nullptr, moved_e.data()}, slot, narrow);
  });
  for (const auto& part : vt_parts) vt_.insert(vt_.end(), part.begin(), part.end());
  for (const auto& part : ee_parts) ee_.insert(ee_.end(), part.begin(), part.end());
  sort_pairs();
}

void SelfCollision::sort_pairs() {
  const int nv = static_cast<int>(tangled_.size()), ne = static_cast<int>(edges_.size());
#pragma omp parallel sections num_threads(2) if (omp_get_max_threads() > 1)
  {
#pragma omp section
    sort_unique_pairs(
        vt_, nv, [](const VT& c) { return c.v; }, [](const VT& c) { return c.f; });
#pragma omp section
    sort_unique_pairs(
        ee_, ne, [](const EE& c) { return c.a; }, [](const EE& c) { return c.b; });
  }
}

std::vector<std::array<int, 2>> SelfCollision::vertex_triangle_pairs() const {
  std::vector<std::array<int, 2>> out;
  for (const VT& c : vt_) out.push_back({c.v, c.f});
  return out;
}

std::vector<std::array<int, 2>> SelfCollision::edge_edge_pairs() const {
  std::vector<std::array<int, 2>> out;
  for (const EE& c : ee_) out.push_back({c.a, c.b});
  return out;
}

bool SelfCollision::narrow_phase(const Narrow& n, int v, int g, VT& out) const {
  const Points3 &x = *n.x, &motion = *n.motion;
  const Vec3 p = x.row(v), a = x.row(F_(g, 0)), b = x.row(F_(g, 1)), c = x.row(F_(g, 2));
  // Relative motion of the vertex against any point of the triangle is bounded by the
  // largest against its corners; each side may also leave its path by `slack`.
  double rel2 = 0;
  for (int i = 0; i < 3; ++i) rel2 = std::max(rel2, (motion.row(v) - motion.row(F_(g, i))).squaredNorm());
  const double rel = std::sqrt(rel2), reach = n.thickness + rel + 2 * n.slack;
  if (box_gap2(p, p, a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c)) > reach * reach * kGapMargin) return false;
  const double d = (p - gdsr::closest_point_on_triangle(p, a, b, c).point).norm();
  if (d >= reach) return false;
  Vec3 bary, nrm;
  double dist = 0;
  if (n.side) {  // the side from other positions (redetect's)
    const Points3& y = *n.side;
    if (!project_on_triangle(y.row(v), y.row(F_(g, 0)), y.row(F_(g, 1)), y.row(F_(g, 2)), bary, nrm, dist))
      return false;
  } else if (!project_on_triangle(p, a, b, c, bary, nrm, dist)) {
    return false;
  }
  out = {v, g, static_cast<signed char>(dist >= 0 ? 1 : -1), static_cast<float>(reach)};
  return true;
}

bool SelfCollision::narrow_phase(const Narrow& n, int ea, int eb, EE& out) const {
  const Points3 &x = *n.x, &motion = *n.motion;
  const int i0 = edges_[ea][0], i1 = edges_[ea][1], j0 = edges_[eb][0], j1 = edges_[eb][1];
  const Vec3 p1 = x.row(i0), q1 = x.row(i1), p2 = x.row(j0), q2 = x.row(j1);
  double rel2 = 0;
  for (int u : edges_[ea])
    for (int w : edges_[eb]) rel2 = std::max(rel2, (motion.row(u) - motion.row(w)).squaredNorm());
  const double rel = std::sqrt(rel2), reach = n.thickness + rel + 2 * n.slack;
  if (box_gap2(p1.cwiseMin(q1), p1.cwiseMax(q1), p2.cwiseMin(q2), p2.cwiseMax(q2)) > reach * reach * kGapMargin)
    return false;
  double s = 0, t = 0;
  closest_segments(p1, q1, p2, q2, s, t);
  Vec3 d = (p1 + s * (q1 - p1)) - (p2 + t * (q2 - p2));
  double len = d.norm();
  if (len >= reach) return false;
  if (n.side) {  // the side from other positions (redetect's)
    const Points3& y = *n.side;
    const Vec3 r1 = y.row(i0), t1 = y.row(i1), r2 = y.row(j0), t2 = y.row(j1);
    closest_segments(r1, t1, r2, t2, s, t);
    d = (r1 + s * (t1 - r1)) - (r2 + t * (t2 - r2));
    len = d.norm();
  }
  out.a = ea;
  out.b = eb;
  out.set_dir(len > 0 ? Vec3(d / len) : Vec3::Zero());
  out.reach = static_cast<float>(reach);
  return true;
}

bool SelfCollision::narrow_phase(const Narrow& n, int e, int f, std::array<int, 2>& out) const {
  const Points3& x = *n.x;
  if (!segment_crosses_triangle(x.row(edges_[e][0]), x.row(edges_[e][1]), x.row(F_(f, 0)), x.row(F_(f, 1)),
                                x.row(F_(f, 2))))
    return false;
  out = {e, f};
  return true;
}

int SelfCollision::untangle(Points3& x, const std::vector<double>& winv, double step) {
  if (crossings_.empty()) return 0;
  untangle_move_.assign(x.rows(), Vec3::Zero());
  int crossing = 0;
  for (const auto& [e, f] : crossings_) {
    const int i0 = edges_[e][0], i1 = edges_[e][1];
    const Vec3 p = x.row(i0), q = x.row(i1), a = x.row(F_(f, 0)), b = x.row(F_(f, 1)), c = x.row(F_(f, 2));
    if (!segment_crosses_triangle(p, q, a, b, c)) continue;
    ++crossing;
    // Moving the edge's side by d against the face slides the crossing point P along the
    // edge (unit E) to stay in the face's plane (unit normal N): dP = d - E (d.N) / (E.N).
    // From P the contour runs into each face of the edge along R (its plane meets the
    // face's along N x M, M its normal; R points into it), so the contour's length changes
    // by -sum R.dP = -d . sum (R - N (E.R) / (E.N)): that sum is the descent direction.
    const Vec3 E = (q - p).normalized(), N = (b - a).cross(c - a).normalized();
    const double EN = E.dot(N);
    if (!(std::abs(EN) > 1e-3)) continue;
    Vec3 d = Vec3::Zero();
    for (int g : edge_faces_[e]) {
      if (g < 0) continue;
      int o = F_(g, 0);
      for (int k = 0; k < 3; ++k)
        if (F_(g, k) != i0 && F_(g, k) != i1) o = F_(g, k);
      const Vec3 ga = x.row(F_(g, 0)), gb = x.row(F_(g, 1)), gc = x.row(F_(g, 2));
      Vec3 R = N.cross((gb - ga).cross(gc - ga));
      if (!(R.norm() > 1e-12)) continue;
      R.normalize();
      Vec3 in = x.row(o).transpose() - p;
      in -= in.dot(E) * E;
      if (R.dot(in) < 0) R = -R;
      d += R - N * (E.dot(R) / EN);
    }
    if (!(d.norm() > 1e-12)) continue;
    d.normalize();
    const double we = 0.5 * (winv[i0] + winv[i1]), wf = (winv[F_(f, 0)] + winv[F_(f, 1)] + winv[F_(f, 2)]) / 3;
    if (!(we + wf > 0)) continue;
    const Vec3 de = d * (step * we / (we + wf)), df = -d * (step * wf / (we + wf));
    for (int i : {i0, i1})
      if (winv[i] > 0) untangle_move_[i] += de;
    for (int k = 0; k < 3; ++k)
      if (winv[F_(f, k)] > 0) untangle_move_[F_(f, k)] += df;
  }
  for (long v = 0; v < x.rows(); ++v) {
    const double len = untangle_move_[v].norm();
    if (len > 0) x.row(v) += (len > step ? untangle_move_[v] * (step / len) : untangle_move_[v]).transpose();
  }
  return crossing;
}

}  // namespace sim

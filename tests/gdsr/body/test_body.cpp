#include "gdsr/body/body.hpp"
#include "gdsr/geometry/self_intersections.hpp"
#include "gdsr/sim/body_landmarks.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <string>

using namespace gdsr;

namespace {

const std::string kBvhTest = "/usr/share/assimp/models/BVH/01_03.bvh";
const std::string kFbx = "/usr/share/assimp/models/FBX/animation_with_skeleton.fbx";

// Every directed edge appears once and its reverse once: closed, consistently oriented.
int bad_edges(const Faces& F) {
  std::map<std::pair<int, int>, int> e;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) e[{F(f, k), F(f, (k + 1) % 3)}]++;
  int bad = 0;
  for (auto& [k, c] : e)
    if (c != 1 || !e.count({k.second, k.first})) ++bad;
  return bad;
}

double volume(const Points3& V, const Faces& F) {
  double v = 0;
  for (int f = 0; f < F.rows(); ++f)
    v += Vec3(V.row(F(f, 0))).dot(Vec3(V.row(F(f, 1))).cross(Vec3(V.row(F(f, 2))))) / 6;
  return v;
}

}  // namespace

TEST_CASE("body: BVH skeleton gives a closed human-sized body in motion") {
  BodyOptions o;
  o.max_seconds = 1.0;
  const BodySequence s = load_body_sequence(kBvhTest, o);
  CHECK(s.from_skeleton);
  CHECK(s.source == kBvhTest);
  CHECK(s.rest_blend_frames == 15);
  CHECK(s.num_frames() == 15 + 31);  // 1 s at 30 fps: 31 samples
  CHECK(s.F.rows() >= 3000);
  CHECK(s.F.rows() <= 8000);
  CHECK(bad_edges(s.F) == 0);
  // Human volume (a 60-80 kg adult is 0.06-0.08 m^3), outward orientation.
  const double vol = volume(s.rest_V, s.F);
  CHECK(vol > 0.04);
  CHECK(vol < 0.11);
  CHECK((s.frames[0] - s.rest_V).cwiseAbs().maxCoeff() == 0.0);
  for (const Points3& X : s.frames) {
    REQUIRE(X.rows() == s.rest_V.rows());
    CHECK(X.allFinite());
    CHECK(volume(X, s.F) == doctest::Approx(vol).epsilon(0.08));  // skinning keeps volume roughly
  }
  // Standing (first motion frame): about opt.height tall.
  const Points3& m0 = s.frames[15];
  CHECK(m0.col(1).maxCoeff() - m0.col(1).minCoeff() == doctest::Approx(o.height).epsilon(0.05));
  // Smooth motion: no teleporting vertices between frames at 30 fps.
  double step = 0;
  for (int t = 1; t < s.num_frames(); ++t)
    step = std::max(step, (s.frames[t] - s.frames[t - 1]).rowwise().norm().maxCoeff());
  CHECK(step < 0.25);  // 7.5 m/s: fast hands are fine, jumps are not
  CHECK(step > 1e-4);  // it does move
  // Landmarks in human ranges, ordered from the floor up.
  const BodyLandmarks& l = s.landmarks;
  CHECK(l.height == o.height);
  CHECK(l.crotch_y > 0.6);
  CHECK(l.crotch_y < l.hips.y);
  CHECK(l.hips.y < l.waist.y);
  CHECK(l.waist.y < l.chest.y);
  CHECK(l.chest.y < l.shoulder_y);
  CHECK(l.shoulder_y < o.height);
  CHECK(l.waist.circumference > 0.6);
  CHECK(l.waist.circumference < 1.0);
  CHECK(l.hips.circumference > l.waist.circumference);
  CHECK(l.hips.circumference < 1.2);
  CHECK(l.hips.half_width > l.hips.half_depth);
}

TEST_CASE("body: every skeleton naming we read gives shoulders, a neck and an upright head") {
  // CMU salsa clips name their joints the Poser way ("rCollar", "rShldr", "lButtock"), the 131
  // walks the cgspeed way ("LeftHip" is the thigh, "LeftShoulder" below "LeftCollar" the upper
  // arm). Until solver revision 5 neither had arms or legs recognised, so the torso was not
  // built: the body was a shoulderless column (its "neck" 0.9x the chest's girth), and a
  // t-shirt slid off it.
  // Also their head's only children are the eyes, 42 degrees off the neck, which tilted the
  // head onto a shoulder. Measured on the rest pose with measure_section (a convex hull).
  const std::string shared = GDSR_SHARED_DIR;
  for (const std::string& path :
       {kBvhTest, shared + "/motions/cmu-salsa/61_02.bvh", shared + "/motions/cmu-walk/131_01.bvh"}) {
    CAPTURE(path);
    BodyOptions o;
    o.max_seconds = 0.1;
    const BodySequence s = load_body_sequence(path, o);
    CHECK(s.torso_found);
    const TriMesh rest = s.rest_mesh();
    const BodyLandmarks& lm = s.landmarks;
    const double ax = lm.chest.cx, az = lm.chest.cz;
    // The neck: the narrowest section between 4 cm above the shoulder joints and the middle
    // of the head (12 cm below its top); the head: its widest section above the neck.
    const double top_y = rest.V.col(1).maxCoeff();
    double neck = 1e9, neck_y = 0, head = 0;
    for (double y = lm.shoulder_y + 0.04; y < top_y - 0.03; y += 0.005) {
      const BodySection sec = measure_section(rest, y, ax, az, 0.25);
      if (y < top_y - 0.12 && sec.circumference < neck) neck = sec.circumference, neck_y = y;
      if (y > neck_y + 0.05) head = std::max(head, sec.circumference);
    }
    MESSAGE(path << ": chest " << lm.chest.circumference << " m, neck " << neck << " m at " << neck_y << " m, head "
                 << head << " m, shoulders at " << lm.shoulder_y << " m");
    CHECK(neck < 0.55 * lm.chest.circumference);  // the column: 0.9x
    CHECK(neck < 0.9 * head);                     // a neck, not a tilted head sunk onto it (0.95x)
    // Upright head: its top straight above the chest's centre.
    Eigen::Index top = 0;
    rest.V.col(1).maxCoeff(&top);
    CHECK(std::hypot(rest.V(top, 0) - ax, rest.V(top, 2) - az) < 0.06);
  }
}

TEST_CASE("body: a rest pose with the arms hanging down is built in a T-pose") {
  // The 131 walks' rest pose has the arms down along the sides. Built there, the arms were
  // fused to the trunk and the garments' waist (sim::measure_body) took them in: 0.25 m from
  // the axis against 0.16 m for 01_03, so the short skirt had 5,032 LR vertices instead of
  // about 930. Since solver revision 6 each hanging upper arm is turned level at its shoulder.
  BodyOptions o;
  o.max_seconds = 0.1;
  const BodySequence walk = load_body_sequence(std::string(GDSR_SHARED_DIR) + "/motions/cmu-walk/131_01.bvh", o);
  const BodySequence ref = load_body_sequence(kBvhTest, o);  // rest pose already a T-pose
  const sim::BodyLandmarks lw = sim::measure_body(walk.rest_mesh()), lr = sim::measure_body(ref.rest_mesh());
  MESSAGE("waist from the axis: 131_01 " << lw.waist_r << " m, 01_03 " << lr.waist_r << " m");
  CHECK(lw.waist_r < 1.2 * lr.waist_r);
  CHECK(lw.waist_r > 0.8 * lr.waist_r);
  // Arms level: the rest pose spans about an arm span sideways, at shoulder height.
  const double span = walk.rest_V.col(0).maxCoeff() - walk.rest_V.col(0).minCoeff();
  const double ref_span = ref.rest_V.col(0).maxCoeff() - ref.rest_V.col(0).minCoeff();
  MESSAGE("rest pose width: 131_01 " << span << " m, 01_03 " << ref_span << " m");
  CHECK(span > 0.85 * ref_span);
  // The motion itself is untouched: after the blend from rest, the arms hang down again.
  const Points3& last = walk.frames.back();
  CHECK(last.col(0).maxCoeff() - last.col(0).minCoeff() < 0.75 * span);
}

TEST_CASE("body: an A-pose rest turns the upper arms and leaves the body and the motion as they are") {
  // The t-shirt is put on an A-pose (sim::rest_arm_drop_degrees): arms 45 degrees below level.
  BodyOptions t, a;
  t.max_seconds = a.max_seconds = 1;
  a.rest_arm_drop_degrees = 45;
  const BodySequence st = load_body_sequence(kBvhTest, t), sa = load_body_sequence(kBvhTest, a);
  REQUIRE(st.rest_V.rows() == sa.rest_V.rows());
  CHECK((st.F - sa.F).cwiseAbs().maxCoeff() == 0);  // the same mesh, built in the file's T-pose
  // The arms' principal lines, measured on the mesh: level before, 45 degrees down after.
  const sim::BodyLandmarks lt = sim::measure_body(st.rest_mesh()), la = sim::measure_body(sa.rest_mesh());
  for (int k = 0; k < 2; ++k) {
    CAPTURE(k);
    REQUIRE(lt.arm_found[k]);
    REQUIRE(la.arm_found[k]);
    const double deg_t = std::asin(-lt.arm_dir[k].y()) * 180 / M_PI, deg_a = std::asin(-la.arm_dir[k].y()) * 180 / M_PI;
    MESSAGE("arm below level: file's rest " << deg_t << " deg, A-pose " << deg_a << " deg");
    CHECK(std::abs(deg_t) < 8);
    CHECK(std::abs(deg_a - 45) < 5);
    CHECK(la.arm_len[k] == doctest::Approx(lt.arm_len[k]).epsilon(0.08));  // the whole arm, hand not cut off
  }
  // Legs and trunk below the armpits do not move; the arms do.
  int moved_low = 0, moved_arm = 0;
  for (Eigen::Index v = 0; v < st.rest_V.rows(); ++v) {
    const double d = (st.rest_V.row(v) - sa.rest_V.row(v)).norm();
    if (st.rest_V(v, 1) < lt.armpit_y - 0.1) moved_low += d > 1e-9;
    if (std::abs(st.rest_V(v, 0) - lt.axis.x()) > 0.4) moved_arm += d > 0.05;
  }
  CHECK(moved_low == 0);
  CHECK(moved_arm > 50);
  // After the rest blend the motion is the same, frame for frame.
  REQUIRE(st.num_frames() == sa.num_frames());
  for (int f = st.rest_blend_frames; f < st.num_frames(); ++f) CHECK(st.frames[f] == sa.frames[f]);
  // Out of range: a clear error.
  BodyOptions bad;
  bad.rest_arm_drop_degrees = 95;
  CHECK_THROWS_WITH_AS(load_body_sequence(kBvhTest, bad), doctest::Contains("rest_arm_drop_degrees"),
                       std::runtime_error);
  bad.rest_arm_drop_degrees = std::nan("");
  CHECK_THROWS_WITH_AS(load_body_sequence(kBvhTest, bad), doctest::Contains("rest_arm_drop_degrees"),
                       std::runtime_error);
}

// Frames where an arm crosses the rest of the body: two body faces intersect (CGAL) whose
// corners were all more than 0.15 m apart in the first frame (a T-pose), not both on one arm
// (more than 0.3 m out to the same side then: an elbow folding onto itself).
static int arm_crossing_frames(const BodySequence& s) {
  const Points3& rest = s.frames[0];
  auto side = [&](int face) {
    const double x = rest(s.F(face, 0), 0);
    return x > 0.3 ? 1 : x < -0.3 ? -1 : 0;
  };
  int n = 0;
  for (int f = 0; f < s.num_frames(); ++f) {
    bool crossing = false;
    for (const auto& [g, h] : self_intersections(s.frames[f], s.F, /*list_pairs=*/true).list) {
      double closest = 1e9;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) closest = std::min(closest, (rest.row(s.F(g, i)) - rest.row(s.F(h, j))).norm());
      crossing = crossing || (closest > 0.15 && (side(g) == 0 || side(g) != side(h)));
    }
    n += crossing;
  }
  return n;
}

TEST_CASE("body: an arm that passes through the hip in the motion is turned out just enough") {
  // CMU 131_02 from 2 s: the walker's forearm swings up to 46 mm into the hip of our rounder
  // capsule body in the clip's first frames (after the 15-frame rest blend).
  const std::string walk = std::string(GDSR_SHARED_DIR) + "/motions/cmu-walk/131_02.bvh";
  BodyOptions as_file, cleared;
  as_file.start_seconds = cleared.start_seconds = 2;
  as_file.max_seconds = cleared.max_seconds = 1;
  cleared.arm_clearance = 0.01;
  const BodySequence a = load_body_sequence(walk, as_file), b = load_body_sequence(walk, cleared);
  CHECK(a.arm_turns.degrees.empty());
  REQUIRE(static_cast<int>(b.arm_turns.degrees.size()) == b.num_frames());
  const int before = arm_crossing_frames(a), after = arm_crossing_frames(b);
  MESSAGE("frames with an arm crossing the body: " << before << " as in the file, " << after << " turned; "
                                                   << b.arm_turns.turned_frames() << " frames turned, up to "
                                                   << b.arm_turns.max_degrees() << " degrees");
  CHECK(before >= 3);
  CHECK(after == 0);
  CHECK(b.arm_turns.still_inside_frames == 0);
  // A few degrees, eased: the turn changes by at most its largest size / 6 frames (0.2 s at 30 fps).
  CHECK(b.arm_turns.max_degrees() > 1);
  CHECK(b.arm_turns.max_degrees() < 20);
  for (int f = 1; f < b.num_frames(); ++f)
    CHECK(std::abs(b.arm_turns.degrees[f] - b.arm_turns.degrees[f - 1]) <= b.arm_turns.max_degrees() / 6 + 1e-9);
  // Frames without a turn are the file's motion to the bit; turned frames move the arms only
  // (the legs, below the hands' reach, stay put).
  CHECK(b.frames[0] == b.rest_V);
  for (int f = 0; f < b.num_frames(); ++f) {
    CAPTURE(f);
    if (b.arm_turns.degrees[f] == 0) {
      CHECK(a.frames[f] == b.frames[f]);
      continue;
    }
    int moved = 0, moved_low = 0;
    for (Eigen::Index v = 0; v < a.frames[f].rows(); ++v) {
      const bool m = (a.frames[f].row(v) - b.frames[f].row(v)).norm() > 1e-6;
      moved += m;
      moved_low += m && a.frames[f](v, 1) < 0.5;
    }
    CHECK(moved > 50);
    CHECK(moved_low == 0);
  }
  BodyOptions bad;
  bad.arm_clearance = -0.01;
  CHECK_THROWS_WITH_AS(load_body_sequence(walk, bad), doctest::Contains("arm_clearance"), std::runtime_error);
}

TEST_CASE("body: a skeleton whose hips are not recognised says so") {
  // 01_03 with its thighs renamed: no hips, so no torso through hips and shoulders.
  const gdsr_test::TempDir dir("body_names");
  const std::string renamed = gdsr_test::bvh_without_thighs(dir, kBvhTest);
  REQUIRE(!renamed.empty());
  BodyOptions o;
  o.max_seconds = 0.1;
  CHECK_FALSE(load_body_sequence(renamed, o).torso_found);
  CHECK(load_body_sequence(kBvhTest, o).torso_found);
}

TEST_CASE("body: rest blend, resampling and start time are consistent") {
  BodyOptions a;
  a.max_seconds = 0.5;
  a.rest_blend_frames = 6;
  BodyOptions b = a;
  b.rest_blend_frames = 0;
  b.fps = 60;
  const BodySequence sa = load_body_sequence(kBvhTest, a);
  const BodySequence sb = load_body_sequence(kBvhTest, b);
  // Same skeleton -> identical body (deterministic meshing).
  REQUIRE(sa.F.rows() == sb.F.rows());
  CHECK((sa.F - sb.F).cwiseAbs().maxCoeff() == 0);
  CHECK(sb.num_frames() == 31);
  CHECK(sb.rest_blend_frames == 0);
  // Frame k at 30 fps (after the blend) == frame 2k at 60 fps.
  for (int k = 0; k <= 15; ++k) CHECK((sa.frames[6 + k] - sb.frames[2 * k]).cwiseAbs().maxCoeff() < 1e-9);
  // Blend frames lie between rest and first motion frame and change monotonically.
  double prev = 0;
  for (int f = 1; f <= 6; ++f) {
    const double d = (sa.frames[f] - sa.rest_V).rowwise().norm().maxCoeff();
    CHECK(d > prev);
    prev = d;
  }
  // start_seconds: the first motion frame is the clip at that time (up to the translation
  // that centres each sequence's rest pose).
  BodyOptions c = b;
  c.start_seconds = 0.25;
  c.max_seconds = 0.1;
  const BodySequence sc = load_body_sequence(kBvhTest, c);
  const Points3 x = sc.frames[0].rowwise() - sc.frames[0].colwise().mean();
  const Points3 y = sb.frames[15].rowwise() - sb.frames[15].colwise().mean();
  CHECK((x - y).cwiseAbs().maxCoeff() < 1e-9);
  CHECK((sc.frames[0] - sb.frames[15]).cwiseAbs().maxCoeff() > 1e-3);  // sanity: it was shifted
  CHECK(sc.num_frames() == 7);
}

TEST_CASE("body: skinned FBX mesh is skinned and animated") {
  BodyOptions o;
  o.rest_blend_frames = 3;
  const BodySequence s = load_body_sequence(kFbx, o);
  CHECK_FALSE(s.from_skeleton);
  CHECK(s.num_frames() > 10);
  CHECK(s.rest_V.rows() > 100);
  CHECK(bad_edges(s.F) == 0);
  CHECK(volume(s.rest_V, s.F) > 0);
  CHECK(s.rest_V.col(1).maxCoeff() - s.rest_V.col(1).minCoeff() == doctest::Approx(o.height));
  double moved = 0;
  for (const Points3& X : s.frames) moved = std::max(moved, (X - s.rest_V).rowwise().norm().maxCoeff());
  CHECK(moved > 0.05);
  // Rest-only loader agrees with frame 0.
  const TriMesh rest = load_body_rest(kFbx, o);
  CHECK((rest.V - s.frames[0]).cwiseAbs().maxCoeff() < 1e-12);
  CHECK_THROWS_WITH_AS(s.frame_mesh(s.num_frames()), doctest::Contains("out of range"), std::runtime_error);
}

TEST_CASE("body: clear errors for bad files and options") {
  CHECK_THROWS_WITH_AS(load_body_sequence("/nonexistent/walk.bvh"), doctest::Contains("/nonexistent/walk.bvh"),
                       std::runtime_error);
  CHECK_THROWS_WITH_AS(load_body_sequence("/usr/share/assimp/models/OBJ/box.obj"), doctest::Contains("no animation"),
                       std::runtime_error);
  BodyOptions bad;
  bad.fps = 0;
  CHECK_THROWS_WITH_AS(load_body_sequence(kBvhTest, bad), doctest::Contains("BodyOptions"), std::runtime_error);
  BodyOptions late;
  late.start_seconds = 1e4;
  CHECK_THROWS_WITH_AS(load_body_sequence(kBvhTest, late), doctest::Contains("start_seconds"), std::runtime_error);
}

TEST_CASE("body: measure_section of a box") {
  // Axis-aligned box 0.4 (x) by 0.2 (z) by 1 (y), closed.
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.V.row(i) << ((i & 1) ? 0.2 : -0.2), ((i & 2) ? 1.0 : 0.0), ((i & 4) ? 0.1 : -0.1);
  m.F.resize(12, 3);
  m.F << 0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3;
  const BodySection s = measure_section(m, 0.5, 0, 0);
  CHECK(s.half_width == doctest::Approx(0.2));
  CHECK(s.half_depth == doctest::Approx(0.1));
  CHECK(s.circumference == doctest::Approx(1.2));
  CHECK_THROWS_AS(measure_section(m, 2.0, 0, 0), std::runtime_error);
}

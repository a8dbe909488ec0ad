// BodyOptions::min_shoulder_half_width: a skeleton whose shoulder joints sit too close together
// for the trunk built around it has them moved out, and its hanging arms leave the trunk.
// Judged by CGAL (a body part inside another, gdsr::body_crosses_itself) and by the rest pose's
// span, not by the code that moves the joints.
#include "gdsr/body/body.hpp"
#include "gdsr/data/validity.hpp"

#include <doctest/doctest.h>

#include <fstream>
#include <string>

using namespace gdsr;

namespace {

constexpr double kPartSeparation = 0.15;  // metres, as ValidityOptions::pinch_separation

int frames_crossing_itself(const BodySequence& s) {
  int n = 0;
  for (const Points3& V : s.frames) n += body_crosses_itself(V, s.F, s.frames.front(), kPartSeparation);
  return n;
}

double span_x(const Points3& V) { return V.col(0).maxCoeff() - V.col(0).minCoeff(); }

}  // namespace

TEST_CASE("body: narrow shoulder joints are moved out, and a salsa dancer's arms leave the trunk") {
  const std::string bvh = std::string(GDSR_SHARED_DIR) + "/motions/cmu-salsa/61_03.bvh";
  REQUIRE_MESSAGE(std::ifstream(bvh).good(), bvh << " is missing (../shared beside the repository)");
  BodyOptions o;
  o.start_seconds = 2;
  o.max_seconds = 4;
  o.arm_clearance = 0;  // the motion as in the file: the joints' move alone
  BodyOptions captured = o;
  captured.min_shoulder_half_width = 0;
  const BodySequence as_filed = load_body_sequence(bvh, captured);
  const BodySequence widened = load_body_sequence(bvh, o);
  MESSAGE("shoulder joints in the file: " << as_filed.captured_shoulder_half_width << " m from the middle");
  CHECK(!as_filed.shoulders_widened);
  CHECK(widened.shoulders_widened);
  CHECK(as_filed.captured_shoulder_half_width < 0.15);
  CHECK(widened.captured_shoulder_half_width == as_filed.captured_shoulder_half_width);
  // The rest pose is a T-pose: each arm moves out by the joints' move, the span by twice it,
  // within 10%: the move is sized with the skeleton's scale (joint extent), the frames are
  // scaled by the mesh's height, a few % apart.
  const double move = o.min_shoulder_half_width - as_filed.captured_shoulder_half_width;
  const double grew = span_x(widened.rest_V) - span_x(as_filed.rest_V);
  MESSAGE("rest pose span grew by " << grew << " m; joints moved " << move << " m each");
  CHECK(std::abs(grew - 2 * move) < 0.1 * 2 * move);
  // As filed, the arms hang inside the trunk through most of the clip. Widened, what is left
  // (75 frames when written) is the motion's own contact: a hand on the hip, a forearm across
  // the waist, the hands meeting in the last frames (capsules of fixed radius overlap there).
  const int before = frames_crossing_itself(as_filed), after = frames_crossing_itself(widened);
  MESSAGE("frames where the body crosses itself, of " << widened.frames.size() << ": " << before << " as filed, "
                                                      << after << " widened");
  CHECK(before > 100);
  CHECK(after < 0.7 * before);
}

TEST_CASE("body: shoulders wider than the limit are left where the file has them") {
  BodyOptions o;
  o.max_seconds = 1;
  BodyOptions captured = o;
  captured.min_shoulder_half_width = 0;
  const BodySequence a = load_body_sequence("/usr/share/assimp/models/BVH/01_03.bvh", o);
  const BodySequence b = load_body_sequence("/usr/share/assimp/models/BVH/01_03.bvh", captured);
  MESSAGE("CMU 01 shoulder joints: " << a.captured_shoulder_half_width << " m from the middle");
  CHECK(a.captured_shoulder_half_width > o.min_shoulder_half_width);
  CHECK(!a.shoulders_widened);
  REQUIRE(a.frames.size() == b.frames.size());
  for (size_t t = 0; t < a.frames.size(); ++t) CHECK(a.frames[t] == b.frames[t]);  // bit for bit
}

TEST_CASE("body: a shoulder width limit out of range is refused") {
  BodyOptions bad;
  bad.min_shoulder_half_width = -0.1;
  CHECK_THROWS_WITH_AS(load_body_sequence("/usr/share/assimp/models/BVH/01_03.bvh", bad),
                       doctest::Contains("min_shoulder_half_width"), std::runtime_error);
}

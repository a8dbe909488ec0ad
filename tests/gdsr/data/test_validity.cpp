// Validity figures of synthetic datasets whose answers are known in closed form: a sheet
// stretched 10% along u (E_u = 0.01), HR lifted 2 mm off the LR (agreement 2 mm), a box body
// rising through the sheet (known depths), an HR frame wrapped 1.25 times round a cylinder
// (self-overlap), and a thin box passing through the sheet between two vertices (threaded).
#include "gdsr/data/validity.hpp"
#include "gdsr/body/body_query.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/wrinkles.hpp"
#include "tests/support/data_fixtures.hpp"
#include "tests/support/grid_garment.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

using gdsr::Points3;

TEST_CASE("gdsr: validity figures of a stretched, lifted sheet over a rising box are the closed-form ones") {
  // Box top per frame; LR vertex (0.165, 0.15, 0) is inside with depth = top, HR's (at z =
  // 2 mm) with depth top - 2 mm; no vertex is nearer a side of the box than to its top.
  const std::vector<double> top = {0.001, 0.004, 0.008, 0.003};
  const gdsr::Dataset d = gdsr_test::stretched_dataset(top);
  gdsr::ValidityOptions opt;
  opt.penetration_limit = 0.0035;
  const gdsr::ValidityFigures v = gdsr::measure_validity(d, opt);
  CHECK(v.frames == 4);
  for (const gdsr::ResolutionValidity* r : {&v.lr, &v.hr}) {
    CHECK(r->si_frames == 4);
    CHECK(r->si_clean_frames == 4);
    CHECK(r->si_clean_fraction() == 1.0);
    CHECK(r->si_max_pairs == 0);
    CHECK(r->strain.E_u == doctest::Approx(0.01).epsilon(1e-9));
    CHECK(r->strain.E_u_stretched == doctest::Approx(0.01).epsilon(1e-9));  // stretched, not shortened
    CHECK(std::abs(r->strain.E_v) < 1e-15);
    CHECK(std::abs(r->strain.E_uv) < 1e-15);
    CHECK(std::abs(r->mean_curvature) < 1e-12);
  }
  CHECK(v.strain_ratio_u() == doctest::Approx(1.0));
  CHECK(std::isnan(v.strain_ratio_v()));  // LR has none: no ratio
  for (const gdsr::ResolutionValidity* r : {&v.lr, &v.hr}) {
    CHECK(r->max_edge_stretch == doctest::Approx(1.1).epsilon(1e-9));  // the edges along u
    CHECK(r->torn_frames == 0);
  }
  CHECK(v.agreement_mean == doctest::Approx(0.002).epsilon(1e-9));
  CHECK(v.agreement_max == doctest::Approx(0.002).epsilon(1e-9));
  CHECK(v.agreement_rest < 1e-12);
  // The 2 mm lift is a shift at the LR scale (barycentric down- and upsampling are exact on
  // an affine shape): all drape, no wrinkles.
  CHECK(v.agreement_lr_scale == doctest::Approx(0.002).epsilon(1e-9));
  CHECK(v.agreement_finer < 1e-12);
  REQUIRE(v.body_measured);
  CHECK(v.lr.max_penetration == doctest::Approx(0.008).epsilon(1e-9));
  CHECK(v.lr.max_penetration_frame == 2);
  CHECK(v.lr.frames_over_limit == 2);  // 4 mm and 8 mm
  CHECK(v.hr.max_penetration == doctest::Approx(0.006).epsilon(1e-9));
  CHECK(v.hr.max_penetration_frame == 2);
  CHECK(v.hr.frames_over_limit == 1);  // 6 mm (2 mm, 1 mm and none in the others)
  // Frame by frame: the box top per frame (LR) and 2 mm less (HR), no pairs, 2 mm apart.
  REQUIRE(v.per_frame.size() == 4);
  for (int t = 0; t < 4; ++t) {
    CAPTURE(t);
    CHECK(v.per_frame[t].lr_pairs == 0);
    CHECK(v.per_frame[t].hr_pairs == 0);
    CHECK(v.per_frame[t].lr_depth == doctest::Approx(top[t]).epsilon(1e-9));
    CHECK(v.per_frame[t].hr_depth == doctest::Approx(std::max(top[t] - 0.002, 0.0)).epsilon(1e-9));
    CHECK(v.per_frame[t].agreement == doctest::Approx(0.002).epsilon(1e-9));
  }
  const std::string csv = gdsr::validity_per_frame_csv(v);
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 5);
  CHECK(csv.find("\n2,0,0,8.00,6.00,2.00,0,0,0\n") != std::string::npos);

  // Without the body: no penetration figures, and the table says so.
  opt.body = false;
  const gdsr::ValidityFigures nb = gdsr::measure_validity(d, opt);
  CHECK_FALSE(nb.body_measured);
  CHECK(nb.lr.max_penetration == 0);
  CHECK(gdsr::validity_table(nb).find("not measured") != std::string::npos);
  CHECK(gdsr::validity_table(v).find("not measured") == std::string::npos);
  CHECK(gdsr::validity_table(v).find("max penetration") != std::string::npos);
}

TEST_CASE("gdsr: validity splits the agreement by scale: a ripple that vanishes on the LR vertices is all wrinkles") {
  gdsr::Dataset d = gdsr_test::stretched_dataset({0.0, 0.0});
  // Flat HR (no lift) plus 3 mm times sin(pi x / 75 mm) of the rest x: zero on every LR vertex
  // (75 mm apart) and +-3 mm on the HR vertices between them, so downsampling sees none of it.
  for (auto& hr : d.hr_frames)
    for (int i = 0; i < hr.rows(); ++i) hr(i, 2) = 0.003 * std::sin(M_PI * d.hr.V(i, 0) / 0.075);
  const gdsr::ValidityFigures v = gdsr::measure_validity(d);
  CHECK(v.agreement_lr_scale < 1e-12);
  CHECK(v.agreement_finer == doctest::Approx(v.agreement_mean).epsilon(1e-12));
  CHECK(v.agreement_finer == doctest::Approx(0.003 * 4 / 9).epsilon(1e-9));  // 4 of the 9 HR columns at 3 mm
}

TEST_CASE("gdsr: validity counts penetration under a second body part as a pinch") {
  // The rising box of the test above plus a "hand" box that is 0.5 m away in frame 0 and, in
  // frame 2 only, hovers 1 cm above the sheet where the body pokes through it (8 mm LR, 6 mm
  // HR): cloth between two parts cannot be outside both, so frame 2 is a pinch frame and the
  // figures outside pinches come from frames 1 and 3.
  const std::vector<double> top = {0.001, 0.004, 0.008, 0.003};
  gdsr::Dataset d = gdsr_test::stretched_dataset(top);
  const gdsr::TriMesh far = gdsr_test::box(0.6, 0.65, 0.13, 0.17, 0.01, 0.05),
                      near = gdsr_test::box(0.14, 0.19, 0.13, 0.17, 0.01, 0.05);
  gdsr_test::add_second_part(d, far, near);
  gdsr::ValidityOptions opt;
  opt.penetration_limit = 0.0035;
  const gdsr::ValidityFigures v = gdsr::measure_validity(d, opt);
  CHECK(v.lr.max_penetration == doctest::Approx(0.008).epsilon(1e-9));  // every vertex still counts here
  CHECK(v.lr.frames_over_limit == 2);
  CHECK(v.lr.max_penetration_free == doctest::Approx(0.004).epsilon(1e-9));
  CHECK(v.lr.max_penetration_free_frame == 1);
  CHECK(v.lr.frames_over_limit_free == 1);
  CHECK(v.lr.pinch_frames == 1);
  CHECK(v.hr.max_penetration_free == doctest::Approx(0.002).epsilon(1e-9));
  CHECK(v.hr.max_penetration_free_frame == 1);
  CHECK(v.hr.frames_over_limit_free == 0);
  CHECK(v.hr.pinch_frames == 1);
  // A reach shorter than the 1 cm gap: no pinch, everything counts (with the crease rule off: the
  // hand's 2 mm over the body is a closed crease to it).
  opt.pinch_reach = 0.005;
  opt.pinch_gap = 0;
  const gdsr::ValidityFigures narrow = gdsr::measure_validity(d, opt);
  CHECK(narrow.lr.max_penetration_free == doctest::Approx(0.008).epsilon(1e-9));
  CHECK(narrow.lr.pinch_frames == 0);
  // The split survives the manifest, and the table prints it.
  const gdsr::ValidityFigures back = gdsr::validity_from_json(gdsr::validity_to_json(v));
  CHECK(back.hr.max_penetration_free == v.hr.max_penetration_free);
  CHECK(back.lr.pinch_frames == 1);
  CHECK(gdsr::validity_table(v).find("pinch frames") != std::string::npos);
  opt.pinch_reach = 0;
  CHECK_THROWS_AS(gdsr::measure_validity(d, opt), gdsr::Error);
}

TEST_CASE("gdsr: body_depths gives each vertex its depth in the body and whether a second part pinches it") {
  // The pinch fixture above, per vertex: LR vertex (0.165, 0.15, 0) is the only one inside the
  // box, as deep as the box top; in frame 2 the "hand" box hovers over it (pinched), in frame 1
  // it is 0.5 m away (not).
  const std::vector<double> top = {0.001, 0.004, 0.008, 0.003};
  gdsr::Dataset d = gdsr_test::stretched_dataset(top);
  gdsr_test::add_second_part(d, gdsr_test::box(0.6, 0.65, 0.13, 0.17, 0.01, 0.05),
                             gdsr_test::box(0.14, 0.19, 0.13, 0.17, 0.01, 0.05));
  for (int t : {1, 2}) {
    CAPTURE(t);
    const Points3& X = d.lr_frames[t];
    const gdsr::BodyDepths bd = gdsr::body_depths(d, t, X);
    REQUIRE(bd.depth.size() == static_cast<size_t>(X.rows()));
    REQUIRE(bd.pinched.size() == static_cast<size_t>(X.rows()));
    for (long i = 0; i < X.rows(); ++i) {
      const bool inside = X(i, 0) > 0.1 && X(i, 0) < 0.2 && X(i, 1) > 0.1 && X(i, 1) < 0.2;
      CAPTURE(i);
      CHECK(bd.depth[i] == doctest::Approx(inside ? top[t] : 0.0).epsilon(1e-9));
      CHECK(bd.pinched[i] == (inside && t == 2));
    }
  }
  // HR is 2 mm higher: 2 mm and 6 mm deep in frames 1 and 2.
  const gdsr::BodyDepths hr = gdsr::body_depths(d, 2, d.hr_frames[2]);
  CHECK(*std::max_element(hr.depth.begin(), hr.depth.end()) == doctest::Approx(0.006).epsilon(1e-9));
  // The reach is an option, as for the figures: 5 mm does not get to the hand 1 cm up (the
  // crease rule off, as above).
  gdsr::ValidityOptions opt;
  opt.pinch_reach = 0.005;
  opt.pinch_gap = 0;
  const gdsr::BodyDepths narrow = gdsr::body_depths(d, 2, d.lr_frames[2], opt);
  CHECK(std::count(narrow.pinched.begin(), narrow.pinched.end(), 1) == 0);
  CHECK_THROWS_AS(gdsr::body_depths(d, 4, d.lr_frames[0]), gdsr::Error);
  CHECK_THROWS_AS(gdsr::body_depths(d, -1, d.lr_frames[0]), gdsr::Error);
  gdsr::Dataset bodiless = gdsr_test::stretched_dataset(top);
  bodiless.body_frames.clear();
  bodiless.body_faces.resize(0, 3);
  CHECK_THROWS_AS(gdsr::body_depths(bodiless, 0, bodiless.lr_frames[0]), gdsr::Error);
}

TEST_CASE("gdsr: validity finds a pinching part by its surface, not its vertices") {
  // As above, but the second part is a broad plate (a hip under a resting hand): 0.6 m square,
  // 1 cm above the sheet in frame 2, its corners 0.3 m or more from the deepest vertex, beyond
  // the 4 cm reach. Its surface is within reach, so frame 2 is a pinch frame all the same.
  const std::vector<double> top = {0.001, 0.004, 0.008, 0.003};
  gdsr::Dataset d = gdsr_test::stretched_dataset(top);
  const gdsr::TriMesh far = gdsr_test::box(1.0, 1.6, -0.15, 0.45, 0.01, 0.05),
                      near = gdsr_test::box(-0.15, 0.45, -0.15, 0.45, 0.01, 0.05);
  gdsr_test::add_second_part(d, far, near);
  // The yardstick's premise: no vertex of the plate is within reach of the sheet's deepest point.
  const double nearest_corner = (near.V.rowwise() - Eigen::RowVector3d(0.165, 0.15, 0)).rowwise().norm().minCoeff();
  REQUIRE(nearest_corner > 0.2);
  gdsr::ValidityOptions opt;
  opt.penetration_limit = 0.0035;
  const gdsr::ValidityFigures v = gdsr::measure_validity(d, opt);
  CHECK(v.lr.pinch_frames == 1);
  CHECK(v.lr.frames_over_limit_free == 1);  // frame 1 (4 mm), the plate 1 m away
  CHECK(v.lr.max_penetration_free == doctest::Approx(0.004).epsilon(1e-9));
  CHECK(v.hr.pinch_frames == 1);
  // The LR vertex is 1 cm under the plate: a reach just short of it finds no pinch (the crease
  // rule off, as above).
  opt.pinch_reach = 0.0099;
  opt.pinch_gap = 0;
  CHECK(gdsr::measure_validity(d, opt).lr.pinch_frames == 0);
  opt.pinch_reach = 0.0101;
  CHECK(gdsr::measure_validity(d, opt).lr.pinch_frames == 1);
}

TEST_CASE("gdsr: validity counts cloth in a closed crease of one part as a pinch, by the gap it is trapped in") {
  // A closed elbow: the rising box of the tests above plus a "forearm" box 1 cm above the sheet
  // in every frame, the same part as the body box (within pinch_separation of it in frame 0),
  // so no second part pinches. The LR vertex (0.165, 0.15, 0) poking 8 mm into the body box in
  // frame 2 lies in a gap of 2 mm between the two (the top at 8 mm, the forearm at 10 mm); in
  // frame 1, 4 mm deep, the gap is 6 mm. Ray from the body's closest point along the way out.
  const std::vector<double> top = {0.001, 0.004, 0.008, 0.003};
  gdsr::Dataset d = gdsr_test::stretched_dataset(top);
  const gdsr::TriMesh forearm = gdsr_test::box(0.14, 0.19, 0.13, 0.17, 0.01, 0.05);
  gdsr_test::add_second_part(d, forearm, forearm);
  gdsr::ValidityOptions opt;
  opt.penetration_limit = 0.0035;
  opt.pinch_gap = 0.005;
  const gdsr::ValidityFigures v = gdsr::measure_validity(d, opt);
  CHECK(v.lr.pinch_frames == 1);  // frame 2
  CHECK(v.lr.max_penetration_free == doctest::Approx(0.004).epsilon(1e-9));
  CHECK(v.lr.max_penetration_free_frame == 1);
  CHECK(v.lr.frames_over_limit_free == 1);
  const gdsr::BodyDepths bd = gdsr::body_depths(d, 2, d.lr_frames[2], opt);
  CHECK(std::count(bd.pinched.begin(), bd.pinched.end(), 1) == 1);
  // A gap wider than pinch_gap is room for the cloth: no pinch, both frames count.
  opt.pinch_gap = 0.0015;
  const gdsr::ValidityFigures wide = gdsr::measure_validity(d, opt);
  CHECK(wide.lr.pinch_frames == 0);
  CHECK(wide.lr.max_penetration_free == doctest::Approx(0.008).epsilon(1e-9));
  CHECK(wide.lr.frames_over_limit_free == 2);
  // Pinch_gap 0 turns the rule off; the default (8 mm) takes frames 1 and 2 as pinches.
  opt.pinch_gap = 0;
  CHECK(gdsr::measure_validity(d, opt).lr.pinch_frames == 0);
  gdsr::ValidityOptions dflt;
  dflt.penetration_limit = 0.0035;
  const gdsr::ValidityFigures by_default = gdsr::measure_validity(d, dflt);
  CHECK(by_default.lr.pinch_frames == 2);
  // The manifest records the gap; manifests from before the rule read 0 (measured without it).
  CHECK(gdsr::validity_from_json(gdsr::validity_to_json(by_default)).pinch_gap == doctest::Approx(0.008));
  nlohmann::json old = gdsr::validity_to_json(by_default);
  old.erase("pinch_gap_m");
  CHECK(gdsr::validity_from_json(old).pinch_gap == 0);
  // The forearm moved aside (not over the closest point's way out): no crease, no pinch.
  gdsr::Dataset aside = gdsr_test::stretched_dataset(top);
  const gdsr::TriMesh beside = gdsr_test::box(0.22, 0.27, 0.13, 0.17, 0.01, 0.05);
  gdsr_test::add_second_part(aside, beside, beside);
  CHECK(gdsr::measure_validity(aside, dflt).lr.pinch_frames == 0);
  CHECK(gdsr::measure_validity(aside, dflt).lr.frames_over_limit_free == 2);
  opt.pinch_gap = -0.001;
  CHECK_THROWS_AS(gdsr::measure_validity(d, opt), gdsr::Error);
}

TEST_CASE("gdsr: validity counts the frames where the body crosses itself, and the pinches among them") {
  // The rising box of the tests above plus two more parts, 0.4-0.5 m away in frame 0: a "hand"
  // that hovers 1 cm above the sheet in frame 2 (a pinch, the body not crossing itself), and an
  // "arm" that in frame 3 is pushed 1 cm into the body box's side below the sheet (the body
  // crosses itself; the LR vertex 3 mm deep there is pinched by it).
  const std::vector<double> top = {0.001, 0.004, 0.008, 0.003};
  gdsr::Dataset d = gdsr_test::stretched_dataset(top);
  const gdsr::TriMesh hand_far = gdsr_test::box(0.6, 0.65, 0.13, 0.17, 0.01, 0.05),
                      hand_near = gdsr_test::box(0.14, 0.19, 0.13, 0.17, 0.01, 0.05),
                      arm_far = gdsr_test::box(0.7, 0.8, 0.13, 0.17, -0.03, -0.005),
                      arm_in = gdsr_test::box(0.19, 0.29, 0.13, 0.17, -0.03, -0.005);
  gdsr::Faces F(36, 3);
  F << d.body_faces, (hand_far.F.array() + 8).matrix(), (arm_far.F.array() + 16).matrix();
  d.body_faces = F;
  for (size_t t = 0; t < d.body_frames.size(); ++t) {
    Points3 V(24, 3);
    V << d.body_frames[t], (t == 2 ? hand_near : hand_far).V, (t == 3 ? arm_in : arm_far).V;
    d.body_frames[t] = V;
  }
  gdsr::ValidityOptions opt;
  opt.penetration_limit = 0.0025;
  const gdsr::ValidityFigures v = gdsr::measure_validity(d, opt);
  CHECK(v.body_crossing_frames == 1);  // frame 3 only
  for (int t = 0; t < 4; ++t) CHECK(v.per_frame[t].body_crossing == (t == 3));
  const std::string csv = gdsr::validity_per_frame_csv(v);  // the last column is body_crosses_itself
  CHECK(csv.substr(csv.size() - 3) == ",1\n");              // frame 3, the last row
  CHECK(csv.find(",1\n") == csv.size() - 3);
  CHECK(v.lr.pinch_frames == 2);       // frames 2 (8 mm, the hand) and 3 (3 mm, the arm)
  CHECK(v.lr.pinch_frames_in_body_crossings == 1);
  CHECK(v.hr.pinch_frames == 1);  // HR is 2 mm higher: 6 mm in frame 2, 1 mm in frame 3
  CHECK(v.hr.pinch_frames_in_body_crossings == 0);
  // Parts that touched in frame 0 are one part: the same crossing no longer counts (a joint's
  // skin creasing as it bends).
  gdsr::Dataset close = d;
  close.body_frames[0].block(16, 0, 8, 3) = arm_in.V;
  close.body_frames[0].block(16, 0, 8, 1).array() += 0.02;  // 1 cm clear of the body box
  CHECK(gdsr::measure_validity(close, opt).body_crossing_frames == 0);
  // Survives the manifest and is printed; manifests without the keys read -1 ("not measured").
  const nlohmann::json j = gdsr::validity_to_json(v);
  const gdsr::ValidityFigures back = gdsr::validity_from_json(j);
  CHECK(back.body_crossing_frames == 1);
  CHECK(back.lr.pinch_frames_in_body_crossings == 1);
  CHECK(gdsr::validity_table(v).find("crosses itself") != std::string::npos);
  nlohmann::json old = j;
  old.erase("body_crossing_frames");
  old["lr"]["body"].erase("pinch_frames_in_body_crossings");
  const gdsr::ValidityFigures o = gdsr::validity_from_json(old);
  CHECK(o.body_crossing_frames == -1);
  CHECK(o.lr.pinch_frames_in_body_crossings == -1);
  CHECK(gdsr::validity_table(o).find("crosses itself") == std::string::npos);
}

TEST_CASE("gdsr: validity counts knots, runs of frames through itself, and those begun where the body crosses itself") {
  // Seven frames of the rising box's sheet (1 mm under it: no pinch); an "arm" 0.4 m away,
  // pushed into the box's side in frames 3-4 (the body crosses itself). The HR sheet is wrapped
  // 1.25 times round a cylinder, through itself, in frames 1, 3, 4 and 6: three knots, {1},
  // {3, 4} (begun in a body crossing) and {6}; LR stays clean.
  gdsr::Dataset d = gdsr_test::stretched_dataset(std::vector<double>(7, 0.001));
  const gdsr::TriMesh arm_far = gdsr_test::box(0.7, 0.8, 0.13, 0.17, -0.03, -0.005),
                      arm_in = gdsr_test::box(0.19, 0.29, 0.13, 0.17, -0.03, -0.005);
  gdsr::Faces F(24, 3);
  F << d.body_faces, (arm_far.F.array() + 8).matrix();
  d.body_faces = F;
  for (size_t t = 0; t < d.body_frames.size(); ++t) {
    Points3 V(16, 3);
    V << d.body_frames[t], (t == 3 || t == 4 ? arm_in : arm_far).V;
    d.body_frames[t] = V;
  }
  const Points3 wrapped = gdsr_test::grid_garment(gdsr_test::GridSpec(8, 8, 0.3, 0.3).bent(2.5 * M_PI)).V;
  REQUIRE(wrapped.rows() == d.hr.V.rows());
  for (int t : {1, 3, 4, 6}) d.hr_frames[t] = wrapped;
  const gdsr::ValidityFigures v = gdsr::measure_validity(d);
  REQUIRE(v.body_crossing_frames == 2);
  // (knots, those begun where the body crosses itself, their frames) of one resolution
  auto knots = [](const gdsr::ResolutionValidity& r) {
    return std::array<int, 3>{r.si_knots, r.si_knots_from_body_crossings, r.si_knot_frames_from_body_crossings};
  };
  CHECK(v.hr.si_clean_frames == 3);
  CHECK(knots(v.hr) == std::array<int, 3>{3, 1, 2});
  CHECK(knots(v.lr) == std::array<int, 3>{0, 0, 0});
  // Every 2nd frame (0, 2, 4, 6): the knots in frames 4 and 6 are one run, begun in a crossing.
  gdsr::ValidityOptions opt;
  opt.intersection_stride = 2;
  const gdsr::ValidityFigures s2 = gdsr::measure_validity(d, opt);
  CHECK(knots(s2.hr) == std::array<int, 3>{1, 1, 2});
  // Without the body: knots counted, their share not measured.
  opt.intersection_stride = 1;
  opt.body = false;
  const gdsr::ValidityFigures nb = gdsr::measure_validity(d, opt);
  CHECK(knots(nb.hr) == std::array<int, 3>{3, -1, -1});
  CHECK(gdsr::validity_table(nb).find("begun where the body crosses itself") == std::string::npos);
  // Survives the manifest and is printed; manifests without the keys read -1 ("not measured").
  const nlohmann::json j = gdsr::validity_to_json(v);
  const gdsr::ValidityFigures back = gdsr::validity_from_json(j);
  CHECK(knots(back.hr) == std::array<int, 3>{3, 1, 2});
  const std::string table = gdsr::validity_table(v);
  CHECK(table.find("self-intersection: knots (runs of frames)              0              3") != std::string::npos);
  CHECK(table.find("begun where the body crosses itself") != std::string::npos);
  CHECK(table.find("1 (2 fr)") != std::string::npos);
  nlohmann::json old = j;
  for (const char* key : {"knots", "knots_from_body_crossings", "knot_frames_from_body_crossings"})
    for (const char* res : {"lr", "hr"}) old[res]["self_intersection"].erase(key);
  const gdsr::ValidityFigures o = gdsr::validity_from_json(old);
  CHECK(knots(o.hr) == std::array<int, 3>{-1, -1, -1});
  CHECK(gdsr::validity_table(o).find("knots") == std::string::npos);
}

TEST_CASE("gdsr: validity names the longest knot's frames and the cloth layers where it began") {
  // The HR sheet of the test above, wrapped 1.25 times round a cylinder (the first fifth of it
  // under the last) in frames 1, 3, 4 and 6: the longest knot is frames 3-4.
  gdsr::Dataset d = gdsr_test::stretched_dataset(std::vector<double>(7, 0.001));
  const Points3 wrapped = gdsr_test::grid_garment(gdsr_test::GridSpec(8, 8, 0.3, 0.3).bent(2.5 * M_PI)).V;
  for (int t : {1, 3, 4, 6}) d.hr_frames[t] = wrapped;
  auto longest = [](const gdsr::ResolutionValidity& r) {
    return std::array<int, 4>{r.si_longest_knot_first, r.si_longest_knot_last, r.si_longest_knot_layers[0],
                              r.si_longest_knot_layers[1]};
  };
  // One layer: frames only. LR has no knot.
  const gdsr::ValidityFigures one = gdsr::measure_validity(d);
  CHECK(longest(one.hr) == std::array<int, 4>{3, 4, -1, -1});
  CHECK(longest(one.lr) == std::array<int, 4>{-1, -1, -1, -1});
  CHECK(one.per_frame[3].hr_layers == std::array<int, 2>{-1, -1});
  // Two layers, split down the middle of the sheet (u): the wrapped end (layer 1) lies over the
  // start (layer 0), so every intersecting pair joins layers 0 and 1.
  double lo = d.hr.V(0, 0), hi = lo;
  for (int i = 0; i < d.hr.V.rows(); ++i) lo = std::min(lo, d.hr.V(i, 0)), hi = std::max(hi, d.hr.V(i, 0));
  const double mid = 0.5 * (lo + hi);
  d.hr.layer.assign(d.hr.V.rows(), 0);
  for (int i = 0; i < d.hr.V.rows(); ++i) d.hr.layer[i] = d.hr.V(i, 0) > mid ? 1 : 0;
  d.lr.layer.assign(d.lr.V.rows(), 0);
  const gdsr::ValidityFigures two = gdsr::measure_validity(d);
  CHECK(longest(two.hr) == std::array<int, 4>{3, 4, 0, 1});
  for (int t : {1, 3, 4, 6}) CHECK(two.per_frame[t].hr_layers == std::array<int, 2>{0, 1});
  CHECK(two.per_frame[2].hr_layers == std::array<int, 2>{-1, -1});  // no pairs
  // The whole sheet one outer layer of a layered garment: a fold through itself, layer 2 twice.
  d.hr.layer.assign(d.hr.V.rows(), 2);
  CHECK(longest(gdsr::measure_validity(d).hr) == std::array<int, 4>{3, 4, 2, 2});
  // Every 2nd frame (0, 2, 4, 6): frames 4 and 6 are one run, the longest.
  gdsr::ValidityOptions opt;
  opt.intersection_stride = 2;
  CHECK(longest(gdsr::measure_validity(d, opt).hr) == std::array<int, 4>{4, 6, 2, 2});
  // Printed, kept by the manifest, absent from older manifests (-1: not measured).
  CHECK(gdsr::validity_table(two).find("3-4, L0-L1") != std::string::npos);
  CHECK(gdsr::validity_table(one).find("longest: frames") != std::string::npos);
  const nlohmann::json j = gdsr::validity_to_json(two);
  CHECK(longest(gdsr::validity_from_json(j).hr) == std::array<int, 4>{3, 4, 0, 1});
  nlohmann::json old = j;
  for (const char* res : {"lr", "hr"}) old[res]["self_intersection"].erase("longest_knot");
  const gdsr::ValidityFigures o = gdsr::validity_from_json(old);
  CHECK(longest(o.hr) == std::array<int, 4>{-1, -1, -1, -1});
  CHECK(gdsr::validity_table(o).find("longest: frames") == std::string::npos);
}

TEST_CASE("gdsr: validity counts the HR frames that overlap themselves, on every k-th frame") {
  gdsr::Dataset d = gdsr_test::wave_dataset(4);
  // Frame 2: the HR sheet wrapped 1.25 times round a cylinder, so a quarter lies on itself.
  d.hr_frames[2] = gdsr_test::grid_garment(gdsr_test::GridSpec(8, 8, 0.3, 0.3).bent(2.5 * M_PI)).V;
  const gdsr::ValidityFigures v = gdsr::measure_validity(d);
  CHECK(v.lr.si_frames == 4);
  CHECK(v.lr.si_clean_frames == 4);
  CHECK(v.hr.si_frames == 4);
  CHECK(v.hr.si_clean_frames == 3);
  CHECK(v.hr.si_clean_fraction() == doctest::Approx(0.75));
  CHECK(v.hr.si_max_frame == 2);
  CHECK(v.hr.si_max_pairs >= 8);  // the second wrap crosses the first in each of the 8 rows of quads
  CHECK(v.hr.si_median_pairs == 0);
  CHECK_FALSE(v.body_measured);
  gdsr::ValidityOptions opt;
  opt.intersection_stride = 2;  // frames 0 and 2
  const gdsr::ValidityFigures s2 = gdsr::measure_validity(d, opt);
  CHECK(s2.hr.si_frames == 2);
  CHECK(s2.hr.si_clean_frames == 1);
  CHECK(s2.hr.si_median_pairs == doctest::Approx(0.5 * v.hr.si_max_pairs));
  opt.intersection_stride = 3;  // frames 0 and 3 miss it
  CHECK(gdsr::measure_validity(d, opt).hr.si_clean_frames == 2);
  opt.intersection_stride = 0;
  CHECK_THROWS_AS(gdsr::measure_validity(d, opt), gdsr::Error);
}

TEST_CASE("gdsr: validity wrinkles: HR ripples above LR upsampled / figures survive the manifest") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(5);
  const gdsr::ValidityFigures v = gdsr::measure_validity(d);
  double up = 0;
  for (const auto& X : d.lr_frames) up += gdsr::wrinkle_measure(gdsr::upsample(d.corr, X), d.hr.F).mean_curvature / 5;
  CHECK(v.upsampled_mean_curvature == doctest::Approx(up).epsilon(1e-12));
  CHECK(v.hr.mean_curvature > 1.5 * v.upsampled_mean_curvature);
  CHECK(v.agreement_mean > 0.001);  // the 4 mm HR ripples
  // The two parts add up to at least the whole (triangle inequality per vertex), and the
  // ripples show as wrinkles.
  CHECK(v.agreement_lr_scale + v.agreement_finer >= v.agreement_mean - 1e-15);
  CHECK(v.agreement_finer > 0.5 * v.agreement_mean);
  CHECK(gdsr::validity_table(v).find("by scale") != std::string::npos);

  gdsr::Dataset w = d;
  w.manifest.validity = gdsr::validity_to_json(v);
  gdsr_test::TempDir dir("validity");
  gdsr::write_dataset(dir / "ds", w);
  const gdsr::Dataset back = gdsr::load_dataset(dir / "ds");
  const gdsr::ValidityFigures r = gdsr::validity_from_json(back.manifest.validity);
  CHECK(gdsr::validity_to_json(r) == gdsr::validity_to_json(v));
  CHECK(r.hr.si_frames == 5);
  CHECK(r.agreement_mean == v.agreement_mean);
  CHECK(gdsr::validity_table(r).find("of E_u: stretched fibres") != std::string::npos);
  // Figures written before E_u was split read NaN and print no split.
  nlohmann::json unsplit = w.manifest.validity;
  for (const char* res : {"lr", "hr"})
    for (const char* k : {"E_u_stretched", "E_v_stretched"}) unsplit[res]["strain"].erase(k);
  const gdsr::ValidityFigures u = gdsr::validity_from_json(unsplit);
  CHECK(std::isnan(u.hr.strain.E_u_stretched));
  CHECK(gdsr::validity_table(u).find("stretched fibres") == std::string::npos);
  // Figures written before the agreement was split by scale read NaN and print no split.
  nlohmann::json unscaled = w.manifest.validity;
  for (const char* k : {"lr_scale_mean", "finer_mean"}) unscaled["agreement_m"].erase(k);
  const gdsr::ValidityFigures us = gdsr::validity_from_json(unscaled);
  CHECK(std::isnan(us.agreement_lr_scale));
  CHECK(std::isnan(us.agreement_finer));
  CHECK(gdsr::validity_table(us).find("by scale") == std::string::npos);
  // A dataset written without figures (as before this field existed) loads with none.
  gdsr::write_dataset(dir / "old", d);
  CHECK(gdsr::load_dataset(dir / "old").manifest.validity.empty());
  nlohmann::json broken = w.manifest.validity;
  broken["hr"].erase("strain");
  CHECK_THROWS_WITH_AS(gdsr::validity_from_json(broken), doctest::Contains("hr.strain"), gdsr::Error);
}

TEST_CASE("gdsr: validity counts the frames where a vertex is dragged out of the cloth") {
  // Frame 2 of the HR pulls one inner vertex 0.15 m out of the sheet (HR edges 0.0375 m in the
  // pattern, stretched 1.1x along u): its edges along u become sqrt(0.04125^2 + 0.15^2) long,
  // 4.15x their pattern length.
  gdsr::Dataset d = gdsr_test::stretched_dataset({0.001, 0.001, 0.001, 0.001});
  const int inner = 4 * 9 + 4;  // (4, 4) of the 9 x 9 HR grid vertices
  REQUIRE(std::abs(d.hr.V(inner, 0) - 0.15) < 1e-9);
  REQUIRE(std::abs(d.hr.V(inner, 1) - 0.15) < 1e-9);
  d.hr_frames[2](inner, 2) += 0.15;
  gdsr::ValidityOptions opt;
  const gdsr::ValidityFigures v = gdsr::measure_validity(d, opt);
  CHECK(v.hr.max_edge_stretch == doctest::Approx(std::hypot(0.04125, 0.15) / 0.0375).epsilon(1e-6));
  CHECK(v.hr.max_edge_stretch_frame == 2);
  CHECK(v.hr.torn_frames == 1);
  CHECK(v.lr.torn_frames == 0);
  CHECK(v.hr.torn_vertices == 9);  // the dragged vertex and its eight neighbours (edges 3.0-4.15x)
  CHECK(v.lr.torn_vertices == 0);
  // A higher threshold counts none; the table prints the figures.
  opt.tear_stretch = 5;
  CHECK(gdsr::measure_validity(d, opt).hr.torn_frames == 0);
  opt.tear_stretch = 1;
  CHECK_THROWS_WITH_AS(gdsr::measure_validity(d, opt), doctest::Contains("tear stretch"), gdsr::Error);
  const std::string table = gdsr::validity_table(v);
  CHECK(table.find("strain: frames with an edge > 2x") != std::string::npos);
  CHECK(table.find("4.15x (f  2)") != std::string::npos);
  CHECK(table.find("cloth vertices on those edges") != std::string::npos);
  // Survives the manifest; a manifest written before the figure existed reads -1 (not measured)
  // and the table leaves the lines out.
  const nlohmann::json j = gdsr::validity_to_json(v);
  const gdsr::ValidityFigures back = gdsr::validity_from_json(j);
  CHECK(back.hr.torn_frames == 1);
  CHECK(back.hr.torn_vertices == 9);
  CHECK(back.hr.max_edge_stretch == v.hr.max_edge_stretch);
  CHECK(back.tear_stretch == 2);
  nlohmann::json old = j;
  for (const char* res : {"lr", "hr"})
    for (const char* k : {"max_edge_stretch", "max_edge_stretch_frame", "torn_frames", "torn_vertices"})
      old[res]["strain"].erase(k);
  old.erase("tear_stretch");
  const gdsr::ValidityFigures o = gdsr::validity_from_json(old);
  CHECK(o.hr.torn_frames == -1);
  CHECK(o.hr.torn_vertices == -1);
  CHECK(gdsr::validity_table(o).find("frames with an edge") == std::string::npos);
}

TEST_CASE("gdsr: validity counts the frames where cloth is threaded on a body part") {
  // The body box of the tests above stays 1 cm under the sheet. In frame 1 a "forearm" box
  // x in [0.05, 0.075], y in [0.065, 0.085], z in [-0.02, 0.02] passes through the sheet between
  // two vertices of the row y = 0.075 (LR x = 0, 0.0825; HR x = 0.04125, 0.0825): the edge
  // between them has both ends outside and its middle 1 cm deep inside (the box's half-width
  // in y). In the other frames the forearm is 0.5 m away.
  gdsr::Dataset d = gdsr_test::stretched_dataset({-0.01, -0.01, -0.01});
  auto with_forearm = [&](double x0, double x1) {
    gdsr::Dataset e = d;
    gdsr_test::add_second_part(e, gdsr_test::box(0.6, 0.65, 0.065, 0.085, -0.02, 0.02),
                               gdsr_test::box(x0, x1, 0.065, 0.085, -0.02, 0.02), 1);
    return e;
  };
  const gdsr::Dataset threaded = with_forearm(0.05, 0.075);
  for (const auto& X : {threaded.lr_frames[1], threaded.hr_frames[1]}) {  // no vertex inside the forearm
    const gdsr::BodyQuery q(gdsr::TriMesh{threaded.body_frames[1], threaded.body_faces});
    REQUIRE(q.closest(X).sdist.minCoeff() > 0);
  }
  gdsr::ValidityOptions opt;
  const gdsr::ValidityFigures v = gdsr::measure_validity(threaded, opt);
  for (const auto* r : {&v.lr, &v.hr}) {
    CHECK(r->threaded_frames == 1);
    CHECK(r->max_threaded_frame == 1);
    CHECK(r->max_threaded_edges >= 1);
    CHECK(r->max_penetration_frame == -1);  // no vertex is inside: only the edges show it
    CHECK(r->torn_frames == 0);
  }
  // Per frame: only frame 1 has threaded edges, and the CSV carries them.
  REQUIRE(v.per_frame.size() == 3);
  CHECK(v.per_frame[1].lr_threaded == v.lr.max_threaded_edges);
  CHECK(v.per_frame[1].hr_threaded == v.hr.max_threaded_edges);
  CHECK(v.per_frame[0].lr_threaded + v.per_frame[2].lr_threaded + v.per_frame[0].hr_threaded +
            v.per_frame[2].hr_threaded ==
        0);
  const std::string csv = gdsr::validity_per_frame_csv(v);
  CHECK(csv.find(",lr_threaded,hr_threaded,body_crosses_itself\n") != std::string::npos);
  CHECK(csv.find("\n1,") != std::string::npos);
  const size_t row1 = csv.find("\n1,") + 1;
  const std::string line1 = csv.substr(row1, csv.find('\n', row1) - row1);
  const std::string tail = "," + std::to_string(v.hr.max_threaded_edges) + ",0";  // hr_threaded, body not crossing
  CHECK(line1.size() > tail.size());
  CHECK(line1.substr(line1.size() - tail.size()) == tail);
  // A deeper threshold than the 1 cm, or a part 6 mm thick (its middle 3 mm deep, as a chord
  // grazing a curved body dips in), counts none.
  opt.threaded_depth = 0.011;
  CHECK(gdsr::measure_validity(threaded, opt).lr.threaded_frames == 0);
  opt.threaded_depth = 0.005;
  const gdsr::ValidityFigures thin = gdsr::measure_validity(with_forearm(0.06, 0.066), opt);
  CHECK(thin.lr.threaded_frames == 0);
  CHECK(thin.hr.threaded_frames == 0);
  opt.threaded_depth = 0;
  CHECK_THROWS_WITH_AS(gdsr::measure_validity(threaded, opt), doctest::Contains("threaded depth"), gdsr::Error);
  // Printed, survives the manifest; manifests written before the figure read -1 and print none.
  const std::string table = gdsr::validity_table(v);
  CHECK(table.find("body: frames with cloth threaded on it") != std::string::npos);
  const nlohmann::json j = gdsr::validity_to_json(v);
  const gdsr::ValidityFigures back = gdsr::validity_from_json(j);
  CHECK(back.hr.threaded_frames == 1);
  CHECK(back.hr.max_threaded_edges == v.hr.max_threaded_edges);
  CHECK(back.threaded_depth == 0.005);
  nlohmann::json old = j;
  for (const char* res : {"lr", "hr"})
    for (const char* k : {"threaded_frames", "max_threaded_edges", "max_threaded_frame"}) old[res]["body"].erase(k);
  const gdsr::ValidityFigures o = gdsr::validity_from_json(old);
  CHECK(o.lr.threaded_frames == -1);
  CHECK(gdsr::validity_table(o).find("threaded") == std::string::npos);
}

#include "gdsr/data/validity_summary.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

using gdsr::ResolutionValidity;
using gdsr::ValidityFigures;

namespace {

// Figures that meet every limit, a little inside each one.
ValidityFigures passing() {
  ValidityFigures v;
  v.frames = 10;
  v.body_measured = true;
  for (ResolutionValidity* r : {&v.lr, &v.hr}) {
    r->si_frames = r->si_clean_frames = 10;
    r->strain.E_u = r->strain.E_v = 0.0015;
    r->strain.E_uv = 0.008;
  }
  v.agreement_mean = 0.015;
  v.hr.mean_curvature = 20;
  v.upsampled_mean_curvature = 18;
  return v;
}

}  // namespace

TEST_CASE("validity summary: each limit, broken alone, is the one named") {
  CHECK(gdsr::failed_criteria(passing()).empty());
  const std::vector<std::pair<std::string, std::function<void(ValidityFigures&)>>> cases = {
      {"clean", [](ValidityFigures& v) { v.hr.si_clean_frames = 9; }},  // 90% < 99%
      {"E_u", [](ValidityFigures& v) { v.lr.strain.E_u = 0.0021; }},
      {"E_v", [](ValidityFigures& v) { v.hr.strain.E_v = 0.0021; }},
      {"E_uv", [](ValidityFigures& v) { v.lr.strain.E_uv = 0.011; }},
      {"E_u HR/LR", [](ValidityFigures& v) { v.hr.strain.E_u = 0.0007; }},  // 0.47x
      {"E_v HR/LR", [](ValidityFigures& v) { v.lr.strain.E_v = 0.0007; }},  // HR 2.1x LR
      {"inside", [](ValidityFigures& v) { v.lr.frames_over_limit_free = 1; }},
      {"torn", [](ValidityFigures& v) { v.hr.torn_frames = 1; }},
      {"threaded", [](ValidityFigures& v) { v.lr.threaded_frames = 2; }},
      {"agreement", [](ValidityFigures& v) { v.agreement_mean = 0.021; }},
      {"wrinkles", [](ValidityFigures& v) { v.hr.mean_curvature = 17; }},
  };
  for (const auto& [name, breaks] : cases) {
    CAPTURE(name);
    ValidityFigures v = passing();
    breaks(v);
    CHECK(gdsr::failed_criteria(v) == std::vector<std::string>{name});
  }
  // Penetration counted under a pinch, and frames not measured (-1), fail nothing.
  ValidityFigures v = passing();
  v.lr.frames_over_limit = v.lr.pinch_frames = 5;
  v.hr.torn_frames = v.lr.threaded_frames = -1;
  CHECK(gdsr::failed_criteria(v).empty());
  // Without a body the body's criteria are not judged.
  v.body_measured = false;
  v.lr.frames_over_limit_free = 3;
  CHECK(gdsr::failed_criteria(v).empty());
}

TEST_CASE("validity summary: a Markdown row per dataset with its figures and what it fails") {
  gdsr::ValiditySummaryRow ok{"clip_a", "skirt_short", passing(), 0.05, 0.5};
  gdsr::ValiditySummaryRow bad{"clip_b", "tshirt", passing(), 0.1, 1.2};
  bad.v.hr.si_clean_frames = 5;
  bad.v.hr.si_knots = 2;  // runs of frames through itself, one of them begun where the body crosses itself
  bad.v.hr.si_knots_from_body_crossings = 1;
  bad.v.lr.si_knots = bad.v.lr.si_knots_from_body_crossings = 0;
  bad.v.body_crossing_frames = 4;
  bad.v.agreement_mean = 0.0305;
  // The stretched-fibre part of the strain, HR over LR (the rest of E_u and E_v is compression).
  ok.v.lr.strain.E_u_stretched = 0.0004, ok.v.hr.strain.E_u_stretched = 0.0003;
  ok.v.lr.strain.E_v_stretched = 0.0005, ok.v.hr.strain.E_v_stretched = 0.0006;
  bad.v.lr.strain.E_u_stretched = bad.v.lr.strain.E_v_stretched = NAN;  // made before the split
  ok.v.hr.torn_vertices = 3;  // the vertices on edges past the tear stretch; -1: made before they were counted
  bad.v.hr.torn_vertices = -1;
  const std::string md = gdsr::validity_summary_markdown({ok, bad});
  CHECK(md.rfind("| dataset | garment | frames |", 0) == 0);
  CHECK(std::count(md.begin(), md.end(), '\n') == 4);  // header, separator, two rows
  CHECK(md.find("| clip_a | skirt_short | 10 | 100.0 / 100.0% | 0.0015 / 0.0015 |") != std::string::npos);
  CHECK(md.find("| 0.0080 / 0.0080 | 0.75x, 1.20x | 0 / 0 (0 / 3 vertices) |") != std::string::npos);
  CHECK(md.find("| 0.0080 / 0.0080 | -, - | 0 / 0 |") != std::string::npos);
  CHECK(md.find("| 15.0 (0.0 / 0.0) | 1.11x | 0.05 / 0.50 | pass |") != std::string::npos);
  CHECK(md.find("| clip_b | tshirt | 10 | 100.0 / 50.0% (knots 0 / 2, 0 / 1 from body crossings) |") !=
        std::string::npos);
  CHECK(md.find("| 30.5 (0.0 / 0.0) | 1.11x | 0.10 / 1.20 | clean, agreement |\n") != std::string::npos);
}

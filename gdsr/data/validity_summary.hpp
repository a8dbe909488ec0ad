// Validity figures of several datasets side by side, one row each, against the limits of a
// physically valid paired simulation (issue 10), for `gdsr data table`: which clips of a recipe
// are fit to learn from, and what fails on the others.
#pragma once

#include "gdsr/data/validity.hpp"

#include <string>
#include <vector>

namespace gdsr {

// The limits a row is held to. Penetration is judged outside pinches: cloth squeezed between two
// body parts is counted apart (validity.hpp).
struct ValidityLimits {
  double clean_fraction = 0.99;  // of checked frames with no self-intersection, each resolution
  double strain_uv = 0.002;      // mean E_u and E_v, each resolution
  double strain_shear = 0.01;    // mean E_uv, each resolution
  double strain_ratio = 2;       // HR / LR of E_u and of E_v within [1/ratio, ratio]
  int penetration_frames = 0;    // frames with cloth deeper than the limit outside pinches, each resolution
  int torn_frames = 0;           // frames with an edge longer than tear_stretch x its pattern
  int threaded_frames = 0;       // frames with cloth threaded on the body
  double agreement = 0.02;       // metres, mean |HR - upsampled LR| over the clip
  double curvature_ratio = 1;    // HR mean curvature over LR upsampled: above this
};

// One dataset's row: its name (a folder), garment, stored figures and seconds per frame (LR, HR;
// NaN when not recorded).
struct ValiditySummaryRow {
  std::string name, garment;
  ValidityFigures v;
  double lr_seconds_per_frame = 0, hr_seconds_per_frame = 0;
};

// The criteria of `lim` that the row fails, by short name ("clean", "E_u", "E_v", "E_uv", "E_u HR/LR",
// "E_v HR/LR", "inside", "torn", "threaded", "agreement", "wrinkles"), in that order; empty: passes.
// Body criteria only when the body was measured.
std::vector<std::string> failed_criteria(const ValidityFigures& v, const ValidityLimits& lim = {});

// A Markdown table (header, separator, one line per row, each ending in '\n'); the last column
// lists the failed criteria ("pass" when none).
std::string validity_summary_markdown(const std::vector<ValiditySummaryRow>& rows, const ValidityLimits& lim = {});

}  // namespace gdsr

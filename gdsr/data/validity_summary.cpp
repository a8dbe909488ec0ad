#include "gdsr/data/validity_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gdsr {
namespace {

std::string format(const char* fmt, double a, double b) {
  char buf[96];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

bool within_ratio(double r, double limit) { return std::isnan(r) || (r <= limit && r >= 1 / limit); }

// "0.84x", or "-" for NaN (not measured: datasets made before the split, or nothing in LR).
std::string ratio_or_dash(double r) { return std::isnan(r) ? "-" : format("%.2fx", r, 0); }

// " (knots 1 / 2, 1 / 1 from body crossings)" when a resolution has knots (ResolutionValidity::si_knots).
std::string knots(const ValidityFigures& v) {
  const ResolutionValidity &L = v.lr, &H = v.hr;
  if (L.si_knots < 0 || H.si_knots < 0 || L.si_knots + H.si_knots == 0) return "";
  std::string s = " (knots " + std::to_string(L.si_knots) + " / " + std::to_string(H.si_knots);
  if (v.body_crossing_frames >= 0 && L.si_knots_from_body_crossings >= 0 && H.si_knots_from_body_crossings >= 0)
    s += ", " + std::to_string(L.si_knots_from_body_crossings) + " / " +
         std::to_string(H.si_knots_from_body_crossings) + " from body crossings";
  return s + ")";
}

}  // namespace

std::vector<std::string> failed_criteria(const ValidityFigures& v, const ValidityLimits& lim) {
  std::vector<std::string> f;
  auto any = [&](auto bad) { return bad(v.lr) || bad(v.hr); };
  if (any([&](const ResolutionValidity& r) { return r.si_clean_fraction() < lim.clean_fraction; }))
    f.push_back("clean");
  if (any([&](const ResolutionValidity& r) { return r.strain.E_u > lim.strain_uv; })) f.push_back("E_u");
  if (any([&](const ResolutionValidity& r) { return r.strain.E_v > lim.strain_uv; })) f.push_back("E_v");
  if (any([&](const ResolutionValidity& r) { return r.strain.E_uv > lim.strain_shear; })) f.push_back("E_uv");
  if (!within_ratio(v.strain_ratio_u(), lim.strain_ratio)) f.push_back("E_u HR/LR");
  if (!within_ratio(v.strain_ratio_v(), lim.strain_ratio)) f.push_back("E_v HR/LR");
  if (v.body_measured &&
      any([&](const ResolutionValidity& r) { return r.frames_over_limit_free > lim.penetration_frames; }))
    f.push_back("inside");
  if (any([&](const ResolutionValidity& r) { return r.torn_frames > lim.torn_frames; })) f.push_back("torn");
  if (v.body_measured && any([&](const ResolutionValidity& r) { return r.threaded_frames > lim.threaded_frames; }))
    f.push_back("threaded");
  if (v.agreement_mean > lim.agreement) f.push_back("agreement");
  if (!(v.hr.mean_curvature > lim.curvature_ratio * v.upsampled_mean_curvature)) f.push_back("wrinkles");
  return f;
}

std::string validity_summary_markdown(const std::vector<ValiditySummaryRow>& rows, const ValidityLimits& lim) {
  std::string s =
      "| dataset | garment | frames | clean LR / HR | E_u LR / HR | E_v LR / HR | E_uv LR / HR | "
      "stretched fibres HR / LR: E_u, E_v | torn LR / HR (their vertices) | "
      "inside, outside pinches: frames LR / HR, deepest mm | pinch frames LR / HR | threaded LR / HR | "
      "body crosses itself | agreement mm (drape / wrinkles) | HR curvature / upsampled LR | s/frame LR / HR | "
      "fails |\n"
      "|---|---|---:|---|---|---|---|---|---|---|---|---|---:|---|---:|---|---|\n";
  for (const ValiditySummaryRow& row : rows) {
    const ValidityFigures& v = row.v;
    const ResolutionValidity &L = v.lr, &H = v.hr;
    std::string fails;
    for (const std::string& c : failed_criteria(v, lim)) fails += (fails.empty() ? "" : ", ") + c;
    s += "| " + row.name + " | " + row.garment + " | " + std::to_string(v.frames) + " | " +
         format("%.1f / %.1f%%", 100 * L.si_clean_fraction(), 100 * H.si_clean_fraction()) + knots(v) + " | " +
         format("%.4f / %.4f", L.strain.E_u, H.strain.E_u) + " | " + format("%.4f / %.4f", L.strain.E_v, H.strain.E_v) +
         " | " + format("%.4f / %.4f", L.strain.E_uv, H.strain.E_uv) + " | " + ratio_or_dash(v.stretched_ratio_u()) +
         ", " + ratio_or_dash(v.stretched_ratio_v()) + " | " + format("%.0f / %.0f", L.torn_frames, H.torn_frames) +
         (L.torn_vertices >= 0 && H.torn_vertices >= 0
              ? format(" (%.0f / %.0f vertices)", L.torn_vertices, H.torn_vertices)
              : std::string()) +
         " | ";
    if (v.body_measured)
      s += format("%.0f / %.0f", L.frames_over_limit_free, H.frames_over_limit_free) +
           format(", %.0f | ", 1e3 * std::max(L.max_penetration_free, H.max_penetration_free), 0) +
           format("%.0f / %.0f", L.pinch_frames, H.pinch_frames) + " | " +
           format("%.0f / %.0f", L.threaded_frames, H.threaded_frames) + " | " +
           std::to_string(v.body_crossing_frames) + " | ";
    else
      s += "no body | | | | ";
    s += format("%.1f (%.1f", 1e3 * v.agreement_mean, 1e3 * v.agreement_lr_scale) +
         format(" / %.1f) | ", 1e3 * v.agreement_finer, 0) +
         format("%.2fx | ", v.hr.mean_curvature / v.upsampled_mean_curvature, 0) +
         format("%.2f / %.2f", row.lr_seconds_per_frame, row.hr_seconds_per_frame) + " | " +
         (fails.empty() ? "pass" : fails) + " |\n";
  }
  return s;
}

}  // namespace gdsr

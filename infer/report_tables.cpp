#include "infer/report_tables.hpp"

#include "gdsr/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gdsr {

std::vector<int> table_steps(int n) {
  std::vector<int> s;
  for (int k : {1, 50, 100, 500, n})
    if (k >= 1 && k <= n && std::find(s.begin(), s.end(), k) == s.end()) s.push_back(k);
  std::sort(s.begin(), s.end());
  return s;
}

namespace {

std::string num(double x, const char* fmt = "%.4f") {
  if (!std::isfinite(x)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, fmt, x);
  return b;
}

std::string step_name(int s) { return s == 1 ? "1-step" : "roll-" + std::to_string(s); }

// A markdown table header: the first `text` columns left-aligned, the numbers right-aligned.
std::string header(const std::vector<std::string>& cols, size_t text = 1) {
  std::string h = "|", rule = "|";
  for (size_t i = 0; i < cols.size(); ++i) h += " " + cols[i] + " |", rule += i < text ? "---|" : "---:|";
  return h + "\n" + rule + "\n";
}

double energy(const StrainEnergies& e, int which) { return which == 0 ? e.E_u : which == 1 ? e.E_v : e.E_uv; }

}  // namespace

std::string report_markdown(const Dataset& d, const Prediction& p, const Evaluation& e, const ReportContext& ctx) {
  const int n = static_cast<int>(e.frames.size());
  if (n == 0) gdsr::fail("report", "the evaluation has no frames");
  const auto steps = table_steps(n);
  const DatasetManifest& m = d.manifest;
  std::string md;
  md += "# GDSR evaluation: " + m.garment + " on " + m.source_motion + "\n\n";
  md += "- dataset: `" + ctx.dataset_path + "`; roll-out of " + std::to_string(n) + " frames (dataset frames " +
        std::to_string(p.first_frame) + ".." + std::to_string(p.first_frame + n - 1) + ") at " + num(m.fps, "%g") +
        " fps\n";
  md += "- LR input " + std::to_string(m.lr_vertices) + " vertices -> HR " + std::to_string(m.hr_vertices) +
        " vertices (" + num(static_cast<double>(m.hr_vertices) / std::max(m.lr_vertices, 1), "%.1f") + "x)\n";
  if (!p.model.empty()) md += "- model: `" + p.model + "`\n";
  md += "- baseline *Upsampled LR*: the LR input carried to the HR mesh by the LR-HR correspondence, no model\n";
  md += "- step s is the s-th predicted frame (the paper's 1-step, roll-50, ...)\n\n";

  std::vector<std::string> cols{"method", "energy"};
  for (int s : steps) cols.push_back(step_name(s));
  cols.push_back("mean");
  md += "## Table 2: stretching and shearing energies under roll-out\n\n";
  md +=
      "Mean over triangles of E_u = (|w_u| - 1)^2, E_v = (|w_v| - 1)^2, E_uv = (w_u . w_v)^2 (paper, appendix B).\n\n";
  md += header(cols, 2);
  const char* names[3] = {"E_u", "E_v", "E_uv"};
  struct Row {
    const char* method;
    StrainEnergies FrameEvaluation::*field;
  };
  for (const Row& r : {Row{"GDSR", &FrameEvaluation::energies}, Row{"Upsampled LR", &FrameEvaluation::energies_lr},
                       Row{"HR simulation", &FrameEvaluation::energies_hr}})
    for (int w = 0; w < 3; ++w) {
      md += std::string("| ") + r.method + " | " + names[w] + " |";
      for (int s : steps) md += " " + num(energy(e.frames[s - 1].*r.field, w)) + " |";
      md += " " + num(energy(e.mean.*r.field, w)) + " |\n";
    }

  int n_ssim = 0;
  for (const auto& f : e.frames) n_ssim += f.has_ssim;
  md += "\n## Table 3: normal-map SSIM\n\n";
  md += "SSIM of UV normal maps (" + std::to_string(d.raster.width) + " x " + std::to_string(d.raster.height) +
        " pixels) against the HR simulation, averaged over " + std::to_string(n_ssim) + " frames (1 is identical).\n\n";
  md +=
      "The whole map counts the UV layout's background, black in both maps (SSIM 1 there); the garment's "
      "pixels alone are the stricter figure.\n\n";
  md += header({"garment", "pixels", "Upsampled LR", "GDSR", "HR at the LR scale"});
  md += "| " + m.garment + " | whole map | " + num(e.mean.ssim_lr) + " | " + num(e.mean.ssim) + " | " +
        num(e.mean.ssim_scale) + " |\n";
  md += "| " + m.garment + " | garment only | " + num(e.mean.ssim_garment_lr) + " | " + num(e.mean.ssim_garment) +
        " | " + num(e.mean.ssim_garment_scale) + " |\n";

  std::vector<std::string> ecols{"method"};
  for (int s : steps) ecols.push_back(step_name(s));
  ecols.push_back("mean");
  md += "\n## Vertex error\n\nMean distance of the HR vertices to the HR simulation, millimetres.\n\n";
  md += header(ecols);
  struct ErrorRow {
    const char* method;
    double FrameEvaluation::*field;
  };
  for (const ErrorRow& r :
       {ErrorRow{"GDSR", &FrameEvaluation::error}, ErrorRow{"Upsampled LR", &FrameEvaluation::error_lr},
        ErrorRow{"HR at the LR scale", &FrameEvaluation::error_scale}}) {
    md += std::string("| ") + r.method + " |";
    for (int s : steps) md += " " + num(1e3 * (e.frames[s - 1].*r.field), "%.2f") + " |";
    md += " " + num(1e3 * (e.mean.*r.field), "%.2f") + " |\n";
  }
  md +=
      "\nHR at the LR scale: the HR simulation downsampled to the LR mesh and upsampled again, what a perfect "
      "correction E without detail would score (in the SSIM table too).\n";

  md += "\n## Table 4: seconds per HR frame\n\n";
  const auto stat = [&](const char* key) {
    return m.stats.contains(key) && m.stats[key].is_number() ? m.stats[key].get<double>() : std::nan("");
  };
  const double hr_s = stat("hr_seconds_per_frame"), lr_s = stat("lr_seconds_per_frame");
  md +=
      "Wall time on this machine: HR simulation (our XPBD solver) against GDSR plus ('+') the LR simulation "
      "it needs.\n\n";
  md += header({"garment", "HR vertices", "HR simulation", "GDSR + LR simulation"});
  md += "| " + m.garment + " | " + std::to_string(m.hr_vertices) + " | " + num(hr_s, "%.3f") + " | " +
        (p.seconds_per_frame > 0 ? num(p.seconds_per_frame, "%.3f") : std::string("-")) + " + " + num(lr_s, "%.3f") +
        " |\n";
  if (!std::isfinite(hr_s)) md += "\n(The dataset records no simulation times.)\n";
  if (!(p.seconds_per_frame > 0)) md += "\n(The prediction records no roll-out time.)\n";

  if (!ctx.image_steps.empty()) {
    md +=
        "\n## Images\n\nLR | GDSR | HR simulation: normal maps in UV (the LR input upsampled to the HR mesh), "
        "then shaded renders from the front and the side.\n";
    for (int s : ctx.image_steps) {
      char name[32];
      std::snprintf(name, sizeof name, "%05d", s);
      md += "\n### " + step_name(s) + " (dataset frame " + std::to_string(p.first_frame + s - 1) + ")\n\n";
      md += "![normal maps, step " + std::to_string(s) + "](images/normals_" + name + ".png)\n\n";
      md += "![shaded, step " + std::to_string(s) + "](images/shaded_" + name + ".png)\n";
    }
  }
  for (const auto& extra : ctx.extra_md) md += "\n" + extra;
  return md;
}

}  // namespace gdsr

// The report folder of `gdsr eval --report DIR` (docs/eval-report.md):
//   report.md          the paper's tables for GDSR and the upsampled LR (report_tables.hpp)
//   report.json        every per-frame figure behind them
//   plots/error.png, plots/ssim.png, plots/energies.png
//   images/normals_SSSSS.png, images/shaded_SSSSS.png   LR | GDSR | HR at roll-out step S
//   rollout.avi        MJPG video LR | GDSR | HR (report_media.hpp)
// `gdsr eval` adds export/ (export_rollout.hpp) and viewer/ (report_viewer.hpp).
#pragma once

#include "gdsr/data/dataset.hpp"
#include "infer/evaluate.hpp"
#include "infer/prediction_io.hpp"

#include <string>
#include <vector>

namespace gdsr {

struct ReportOptions {
  std::string dataset_path;      // named in the report
  std::vector<int> image_steps;  // roll-out steps (1-based) with images; empty: table_steps
  bool video = true;
  int video_every = 1;                // every k-th frame in the video
  std::vector<std::string> extra_md;  // further markdown sections (exports, viewer)
};

// Writes the folder (created if missing); returns the paths written, relative to dir.
// Throws gdsr::Error on a step outside the roll-out or an I/O failure.
std::vector<std::string> write_eval_report(const std::string& dir, const Dataset& d, const Prediction& p,
                                           const Evaluation& e, const ReportOptions& opt = {});

}  // namespace gdsr

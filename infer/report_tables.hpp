// The evaluation report's text: the paper's tables (Table 2: E_u, E_v, E_uv under roll-out;
// Table 3: normal-map SSIM averaged over the clip; Table 4: seconds per HR frame) and the
// vertex error, for GDSR and the plain upsampling of the LR input, as markdown.
//
// Roll-out step s (s = 1, 2, ...) is the s-th predicted frame, G[s - 1], dataset frame
// first_frame + s - 1; the paper's "1-step" and "roll-50" are steps 1 and 50.
#pragma once

#include "gdsr/data/dataset.hpp"
#include "infer/evaluate.hpp"
#include "infer/prediction_io.hpp"

#include <string>
#include <vector>

namespace gdsr {

// The steps of Table 2 that exist in a roll-out of n frames: 1, 50, 100, 500 and n, in
// increasing order, without repeats.
std::vector<int> table_steps(int n);

struct ReportContext {
  std::string dataset_path;           // as given on the command line
  std::vector<int> image_steps;       // steps with images under images/
  std::vector<std::string> extra_md;  // further sections (plots, video, exports), appended as is
};

// The whole report.md. Throws gdsr::Error when e has no frames.
std::string report_markdown(const Dataset& d, const Prediction& p, const Evaluation& e, const ReportContext& ctx);

}  // namespace gdsr

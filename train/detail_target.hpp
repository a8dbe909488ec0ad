// The fine-loss target of `gdsr train --fine-target detail`: the HR simulation's own detail
// carried onto the model's coarse shape, so that A learns wrinkles rather than the drape
// difference between the LR and HR simulations (E's job). For HR vertex i on LR triangle f:
//   G*_i = up(C^)_i + R_f(C^) R_f(C*)^T (HR_i - up(C*)_i)
// with C* = downsample(HR) the coarse truth, up the barycentric upsample of the LR-HR
// correspondence and R_f the local frame of triangle f (gdsr/model/frames.hpp, the frames A
// decodes its residual in). With C^ = C* the target is the HR frame itself; a rigid motion of
// C^ moves the target rigidly with it. Positions in metres.
#pragma once

#include "gdsr/geometry/correspondence.hpp"

#include <vector>

namespace gdsr {

// hr: the HR frame; coarse_truth: downsample(c, hr); C_hat: the model's corrected LR frame.
// Returns hr with the rows `vertices` replaced by their target (the others are untouched).
Points3 detail_target(const Correspondence& c, const Points3& hr, const Points3& coarse_truth, const Points3& C_hat,
                      const std::vector<int>& vertices, double frame_eps);

}  // namespace gdsr

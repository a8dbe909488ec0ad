// Pictures of an evaluation: per-frame plots, LR | GDSR | HR panels (UV normal maps and
// shaded renders) and a video of the roll-out. Images are BGR CV_8UC3.
#pragma once

#include "gdsr/data/dataset.hpp"
#include "infer/evaluate.hpp"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace gdsr {

// Vertex error (mm), SSIM and the three energies per dataset frame, GDSR against the
// upsampled LR (error and SSIM: and the HR simulation at the LR scale; energies: and the HR
// simulation).
cv::Mat plot_error(const Evaluation& e);
cv::Mat plot_ssim(const Evaluation& e);  // frames with SSIM only; throws if there are none
cv::Mat plot_energies(const Evaluation& e);

// Normal maps in UV of the upsampled LR input | G | the HR simulation of dataset frame t,
// each resized to `size` pixels square, labelled.
cv::Mat normal_map_panel(const Dataset& d, const Points3& G, int t, int size = 400);

// Shaded renders LR input | G | HR simulation of dataset frame t, one row per view direction
// (front, side), one camera per row shared by the three meshes.
cv::Mat shaded_panel(const Dataset& d, const Points3& G, int t, int size = 360);

// MJPG .avi (OpenCV's own writer, no codec library needed) of LR | GDSR | HR renders from the
// front, every k-th frame of G (dataset frames first_frame + k), at the dataset's fps / every,
// one camera for the whole clip. Written to path + ".tmp.avi", then renamed. Returns the
// number of video frames. Throws gdsr::Error when the writer cannot open.
int write_rollout_video(const std::string& path, const Dataset& d, const std::vector<Points3>& G, int first_frame,
                        int every = 1, int size = 320);

}  // namespace gdsr

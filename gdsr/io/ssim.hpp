// SSIM (Wang, Bovik, Sheikh and Simoncelli 2004) of two colour images with OpenCV's quality
// module (Gaussian window 11, sigma 1.5): over the whole image, and over a mask's pixels only.
#pragma once

#include <opencv2/core.hpp>

namespace gdsr {

// Mean SSIM over the three channels of two CV_32FC3 images with values in 0..1.
double ssim(const cv::Mat& a, const cv::Mat& b);

// SSIM averaged over the whole image and over the mask's pixels only. On a whole UV normal map
// the layout's background, black in both maps, scores SSIM 1 and dilutes every difference in
// proportion to its area (85% of the 1024^2 raster for the demo's skirt, whose whole-map SSIMs
// of 0.97-0.98 are 0.79-0.88 on the garment: the range of the paper's Table 3). The masked
// figure is the SSIM map's mean where `mask` (CV_8U, the images' size) is non-zero, windows at
// the mask's border included as they are. Throws if the mask is empty or sizes differ.
struct SsimScore {
  double whole = 0;
  double garment = 0;
};
SsimScore ssim_score(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask);

}  // namespace gdsr

#include "gdsr/io/ssim.hpp"

#include "gdsr/error.hpp"

#include <opencv2/quality/qualityssim.hpp>

namespace gdsr {

namespace {

// OpenCV's SSIM constants C1 = (0.01 * 255)^2, C2 = (0.03 * 255)^2 assume 0..255 pixels.
cv::Mat to_255(const cv::Mat& a) {
  cv::Mat out;
  a.convertTo(out, CV_32F, 255.0);
  return out;
}

double channel_mean(const cv::Scalar& s) { return (s[0] + s[1] + s[2]) / 3.0; }

}  // namespace

double ssim(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) gdsr::fail("ssim", "images differ in size or type");
  return channel_mean(cv::quality::QualitySSIM::compute(to_255(a), to_255(b), cv::noArray()));
}

SsimScore ssim_score(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  if (a.size() != b.size() || a.type() != b.type()) gdsr::fail("ssim", "images differ in size or type");
  if (mask.size() != a.size() || mask.type() != CV_8U)
    gdsr::fail("ssim", "the mask is not a CV_8U image of the images' size");
  if (cv::countNonZero(mask) == 0) gdsr::fail("ssim", "the mask is empty");
  cv::Mat map;
  const cv::Scalar whole = cv::quality::QualitySSIM::compute(to_255(a), to_255(b), map);
  return {channel_mean(whole), channel_mean(cv::mean(map, mask))};
}

}  // namespace gdsr

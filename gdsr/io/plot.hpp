// Line plots drawn with OpenCV (imgproc): several series on shared axes, "nice" ticks with
// labels, a grid and a legend. For the evaluation report's per-frame curves.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace gdsr {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;                     // same length; non-finite points are skipped
  cv::Scalar colour = cv::Scalar(200, 80, 30);  // BGR
};

struct PlotOptions {
  std::string title, x_label, y_label;
  int width = 900, height = 360;  // pixels
  bool y_from_zero = false;       // include 0 in the y range
};

// A BGR CV_8UC3 image of width x height. Throws gdsr::Error when there is no finite point or
// a series' x and y differ in length.
cv::Mat line_plot(const std::vector<PlotSeries>& series, const PlotOptions& opt = {});

// Up to n + 1 "nice" tick values (steps of 1, 2 or 5 times a power of ten) covering [lo, hi].
std::vector<double> nice_ticks(double lo, double hi, int n = 5);

}  // namespace gdsr

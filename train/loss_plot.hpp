// A loss-curve picture (OpenCV): totals against the step, log10 scale on y, decade grid lines.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace gdsr {

struct PlotSeries {
  std::string name;
  std::vector<std::pair<int64_t, double>> points;  // (step, value > 0; others are skipped)
  int b = 0, g = 0, r = 0;                          // colour
  bool markers = false;                             // dots on every point (sparse series)
};

// Draws the series into a width x height PNG at `path` (temp file + rename); throws naming
// the file when it cannot be written.
void draw_loss_plot(const std::string& path, const std::string& title, const std::vector<PlotSeries>& series,
                    int width = 900, int height = 500);

}  // namespace gdsr

#include "gdsr/io/plot.hpp"

#include "gdsr/error.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace gdsr {

std::vector<double> nice_ticks(double lo, double hi, int n) {
  if (!(hi > lo)) return {lo};
  const double raw = (hi - lo) / std::max(n, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> t;
  for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step)
    t.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  return t;
}

namespace {

std::string tick_label(double v, double step) {
  char b[32];
  const int digits = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  if (std::abs(v) >= 1e5 || (v != 0 && std::abs(v) < 1e-4))
    std::snprintf(b, sizeof b, "%.2g", v);
  else
    std::snprintf(b, sizeof b, "%.*f", std::min(digits, 6), v);
  return b;
}

}  // namespace

cv::Mat line_plot(const std::vector<PlotSeries>& series, const PlotOptions& opt) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : series) {
    if (s.x.size() != s.y.size()) gdsr::fail("line_plot", "series '" + s.label + "' has x and y of different lengths");
    for (size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
        y0 = std::min(y0, s.y[i]), y1 = std::max(y1, s.y[i]);
      }
  }
  if (!std::isfinite(x0)) gdsr::fail("line_plot", "no finite point to plot ('" + opt.title + "')");
  if (opt.y_from_zero) y0 = std::min(y0, 0.0), y1 = std::max(y1, 0.0);
  if (x1 <= x0) x0 -= 0.5, x1 += 0.5;
  if (y1 <= y0) {
    const double pad = y0 != 0 ? 0.05 * std::abs(y0) : 1.0;
    y0 -= pad, y1 += pad;
  } else {
    const double pad = 0.05 * (y1 - y0);
    y1 += pad;
    if (!(opt.y_from_zero && y0 == 0)) y0 -= pad;
  }
  cv::Mat img(opt.height, opt.width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const double fs = 0.45;
  const int left = 80, right = 20, top = 34, bottom = 48;
  const int pw = opt.width - left - right, ph = opt.height - top - bottom;
  if (pw < 20 || ph < 20) gdsr::fail("line_plot", "image too small");
  const auto px = [&](double x) { return left + static_cast<int>(std::lround((x - x0) / (x1 - x0) * pw)); };
  const auto py = [&](double y) { return top + ph - static_cast<int>(std::lround((y - y0) / (y1 - y0) * ph)); };

  const cv::Scalar grid(225, 225, 225), axis(60, 60, 60), text(30, 30, 30);
  const auto xt = nice_ticks(x0, x1, 8), yt = nice_ticks(y0, y1, 5);
  const double xs = xt.size() > 1 ? xt[1] - xt[0] : 1, ys = yt.size() > 1 ? yt[1] - yt[0] : 1;
  for (double v : xt) {
    cv::line(img, {px(v), top}, {px(v), top + ph}, grid, 1);
    const std::string l = tick_label(v, xs);
    int base = 0;
    const cv::Size sz = cv::getTextSize(l, font, fs, 1, &base);
    cv::putText(img, l, {px(v) - sz.width / 2, top + ph + 18}, font, fs, text, 1, cv::LINE_AA);
  }
  for (double v : yt) {
    cv::line(img, {left, py(v)}, {left + pw, py(v)}, grid, 1);
    const std::string l = tick_label(v, ys);
    int base = 0;
    const cv::Size sz = cv::getTextSize(l, font, fs, 1, &base);
    cv::putText(img, l, {left - 6 - sz.width, py(v) + sz.height / 2}, font, fs, text, 1, cv::LINE_AA);
  }
  cv::rectangle(img, {left, top}, {left + pw, top + ph}, axis, 1);

  for (const auto& s : series) {
    std::vector<cv::Point> run;
    const auto flush = [&]() {
      if (run.size() == 1) cv::circle(img, run[0], 2, s.colour, -1, cv::LINE_AA);
      if (run.size() > 1) cv::polylines(img, run, false, s.colour, 2, cv::LINE_AA);
      run.clear();
    };
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i]))
        run.emplace_back(px(s.x[i]), py(s.y[i]));
      else
        flush();
    }
    flush();
  }
  // Title, axis labels and the legend (top right, inside the plot).
  cv::putText(img, opt.title, {left, 22}, font, 0.6, text, 1, cv::LINE_AA);
  if (!opt.x_label.empty()) {
    int base = 0;
    const cv::Size sz = cv::getTextSize(opt.x_label, font, fs, 1, &base);
    cv::putText(img, opt.x_label, {left + pw / 2 - sz.width / 2, opt.height - 10}, font, fs, text, 1, cv::LINE_AA);
  }
  if (!opt.y_label.empty()) {
    int base = 0;
    const cv::Size sz = cv::getTextSize(opt.y_label, font, fs, 1, &base);
    cv::Mat label(sz.height + base + 4, sz.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(label, opt.y_label, {2, sz.height + 1}, font, fs, text, 1, cv::LINE_AA);
    cv::rotate(label, label, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int y = std::max(0, top + ph / 2 - label.rows / 2);
    if (label.rows + y <= img.rows && label.cols <= left) label.copyTo(img(cv::Rect(2, y, label.cols, label.rows)));
  }
  // Legend in the title row, right-aligned, entries side by side.
  int x = left + pw;
  for (auto it = series.rbegin(); it != series.rend(); ++it) {
    int base = 0;
    x -= cv::getTextSize(it->label, font, fs, 1, &base).width + 30 + 14;
    cv::line(img, {x, 17}, {x + 24, 17}, it->colour, 2, cv::LINE_AA);
    cv::putText(img, it->label, {x + 30, 22}, font, fs, text, 1, cv::LINE_AA);
  }
  return img;
}

}  // namespace gdsr

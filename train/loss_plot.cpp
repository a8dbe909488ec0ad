#include "train/loss_plot.hpp"

#include "gdsr/error.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace gdsr {

void draw_loss_plot(const std::string& path, const std::string& title, const std::vector<PlotSeries>& series,
                    int width, int height) {
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 80, right = 20, top = 40, bottom = 50;
  const cv::Rect area(left, top, width - left - right, height - top - bottom);
  int64_t x_max = 1;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const PlotSeries& s : series)
    for (const auto& [x, y] : s.points)
      if (y > 0 && std::isfinite(y)) {
        x_max = std::max(x_max, x);
        lo = std::min(lo, std::log10(y));
        hi = std::max(hi, std::log10(y));
      }
  if (!std::isfinite(lo)) lo = -1, hi = 0;
  lo = std::floor(lo);
  hi = std::max(std::ceil(hi), lo + 1);
  auto px = [&](int64_t x, double y) {
    const double u = static_cast<double>(x) / static_cast<double>(x_max);
    const double v = (std::log10(y) - lo) / (hi - lo);
    return cv::Point(area.x + static_cast<int>(std::lround(u * area.width)),
                     area.y + area.height - static_cast<int>(std::lround(v * area.height)));
  };
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  const cv::Scalar grey(200, 200, 200), black(0, 0, 0);
  for (int e = static_cast<int>(lo); e <= static_cast<int>(hi); ++e) {
    const int y = px(0, std::pow(10.0, e)).y;
    cv::line(img, {area.x, y}, {area.x + area.width, y}, grey, 1);
    cv::putText(img, "1e" + std::to_string(e), {8, y + 5}, font, 0.45, black, 1, cv::LINE_AA);
    if (hi - lo > 3 || e == static_cast<int>(hi)) continue;
    for (int m : {2, 5}) {  // minor lines when few decades show
      const int ym = px(0, m * std::pow(10.0, e)).y;
      cv::line(img, {area.x, ym}, {area.x + area.width, ym}, cv::Scalar(235, 235, 235), 1);
      cv::putText(img, std::to_string(m) + "e" + std::to_string(e), {8, ym + 5}, font, 0.4, cv::Scalar(90, 90, 90), 1,
                  cv::LINE_AA);
    }
  }
  for (int i = 0; i <= 4; ++i) {
    const int64_t step = x_max * i / 4;
    const int x = area.x + area.width * i / 4;
    cv::line(img, {x, area.y + area.height}, {x, area.y + area.height + 5}, black, 1);
    cv::putText(img, std::to_string(step), {x - 15, area.y + area.height + 22}, font, 0.45, black, 1, cv::LINE_AA);
  }
  cv::rectangle(img, area, black, 1);
  cv::putText(img, "step", {area.x + area.width / 2 - 15, height - 8}, font, 0.5, black, 1, cv::LINE_AA);
  cv::putText(img, title, {area.x, 25}, font, 0.6, black, 1, cv::LINE_AA);

  int legend_y = area.y + 20;
  for (const PlotSeries& s : series) {
    const cv::Scalar colour(s.b, s.g, s.r);
    std::vector<cv::Point> pts;
    for (const auto& [x, y] : s.points)
      if (y > 0 && std::isfinite(y)) pts.push_back(px(x, y));
    if (pts.size() > 1) cv::polylines(img, pts, false, colour, 1, cv::LINE_AA);
    if (s.markers || pts.size() == 1)
      for (const cv::Point& p : pts) cv::circle(img, p, 3, colour, cv::FILLED, cv::LINE_AA);
    const int lx = area.x + area.width - 230;
    cv::line(img, {lx, legend_y - 4}, {lx + 25, legend_y - 4}, colour, 2);
    cv::putText(img, s.name, {lx + 32, legend_y}, font, 0.45, black, 1, cv::LINE_AA);
    legend_y += 20;
  }

  const std::string tmp = path + ".tmp.png";
  bool ok = false;
  try {
    ok = cv::imwrite(tmp, img);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    gdsr::fail(path, "cannot write the loss plot");
  }
}

}  // namespace gdsr

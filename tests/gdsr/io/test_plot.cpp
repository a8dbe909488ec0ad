// Line plots (gdsr/io/plot.hpp): tick values, and the curves land where the axes say.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "gdsr/io/plot.hpp"

#include <cmath>

TEST_CASE("plot: nice ticks are 1 2 5 steps covering the range") {
  CHECK(gdsr::nice_ticks(0, 10, 5) == std::vector<double>{0, 2, 4, 6, 8, 10});
  const auto t = gdsr::nice_ticks(0.013, 0.047, 5);
  REQUIRE(t.size() >= 3);
  CHECK(t.front() >= 0.013 - 1e-12);
  CHECK(t.back() <= 0.047 + 1e-12);
  CHECK(t[1] - t[0] == doctest::Approx(0.01));  // raw step 0.0068 rounds up to 1e-2
  CHECK(gdsr::nice_ticks(0.013, 0.047, 10)[1] - gdsr::nice_ticks(0.013, 0.047, 10)[0] == doctest::Approx(0.005));
  CHECK(gdsr::nice_ticks(3, 3).size() == 1);
}

TEST_CASE("plot: two series in their colours and no finite point refused") {
  gdsr::PlotSeries rising{"rising", {0, 1, 2, 3}, {0, 1, 2, 3}, cv::Scalar(255, 0, 0)};
  gdsr::PlotSeries flat{"flat", {0, 1, 2, 3}, {3, 3, std::nan(""), 3}, cv::Scalar(0, 0, 255)};
  gdsr::PlotOptions o;
  o.title = "test";
  const cv::Mat img = gdsr::line_plot({rising, flat}, o);
  REQUIRE(img.type() == CV_8UC3);
  CHECK(img.cols == o.width);
  CHECK(img.rows == o.height);
  // Count pure-ish blue and red pixels: both curves are drawn.
  int blue = 0, red = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      blue += p[0] > 200 && p[1] < 60 && p[2] < 60;
      red += p[2] > 200 && p[0] < 60 && p[1] < 60;
    }
  CHECK(blue > 200);
  CHECK(red > 100);
  // The rising line goes from bottom left to top right of the plot area.
  int first_row_left = -1;
  for (int y = 0; y < img.rows && first_row_left < 0; ++y)
    for (int x = 80; x < 100; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      if (p[0] > 200 && p[1] < 60 && p[2] < 60) first_row_left = y;
    }
  CHECK(first_row_left > img.rows / 2);

  CHECK_THROWS_AS(gdsr::line_plot({{"nan", {0}, {std::nan("")}, cv::Scalar(0, 0, 0)}}), gdsr::Error);
  CHECK_THROWS_AS(gdsr::line_plot({{"ragged", {0, 1}, {0}, cv::Scalar(0, 0, 0)}}), gdsr::Error);
}

// gdsr::ssim_score against the closed form of two flat images (Wang et al. 2004).
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "gdsr/io/ssim.hpp"

#include <cmath>

TEST_CASE(
    "ssim: over the mask's pixels it is the closed form of two flat images, and the background dilutes the whole") {
  // Two maps flat at a and b over the "garment" (the left half), black beyond it. Where the whole
  // 11 x 11 window lies on the garment both variances are 0, so SSIM = (2 a b + C1) / (a^2 + b^2 + C1),
  // C1 = (0.01 * 255)^2 on 0..255 pixels (Wang et al. 2004): closed form, not OpenCV's code.
  const int n = 256;
  const double a = 0.2, b = 0.8;
  cv::Mat A(n, n, CV_32FC3, cv::Scalar(0, 0, 0)), B = A.clone(), garment(n, n, CV_8U, cv::Scalar(0));
  A(cv::Rect(0, 0, n / 2, n)).setTo(cv::Scalar(a, a, a));
  B(cv::Rect(0, 0, n / 2, n)).setTo(cv::Scalar(b, b, b));
  garment(cv::Rect(0, 0, n / 2, n)).setTo(255);
  const double C1 = std::pow(0.01 * 255, 2), a255 = 255 * a, b255 = 255 * b;
  const double flat = (2 * a255 * b255 + C1) / (a255 * a255 + b255 * b255 + C1);  // 0.4706

  // Only pixels whose window stays inside the garment (6 px from its edge; OpenCV reflects at the
  // image border, which keeps flat maps flat): float maps, so 1e-5.
  cv::Mat interior(n, n, CV_8U, cv::Scalar(0));
  interior(cv::Rect(0, 0, n / 2 - 6, n)).setTo(255);
  CHECK(gdsr::ssim_score(A, B, interior).garment == doctest::Approx(flat).epsilon(1e-5));

  // The whole garment: its 5-column rim mixes in the black, 5 of 128 columns, so within 0.04 of flat;
  // the whole map scores the background's half 1, as the background dilutes every difference.
  const gdsr::SsimScore s = gdsr::ssim_score(A, B, garment);
  CHECK(std::abs(s.garment - flat) < 0.04);
  CHECK(std::abs(s.whole - 0.5 * (1 + flat)) < 0.04);
  CHECK(s.whole == doctest::Approx(gdsr::ssim(A, B)).epsilon(1e-12));
  CHECK(gdsr::ssim_score(A, A, garment).garment == doctest::Approx(1).epsilon(1e-6));
  CHECK_THROWS_AS(gdsr::ssim_score(A, B, cv::Mat(n, n, CV_8U, cv::Scalar(0))), gdsr::Error);  // empty mask
  CHECK_THROWS_AS(gdsr::ssim_score(A, B, cv::Mat(n / 2, n, CV_8U, cv::Scalar(255))), gdsr::Error);
}

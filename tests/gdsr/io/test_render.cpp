#include "gdsr/io/render.hpp"

#include <doctest/doctest.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

using namespace gdsr;

namespace {

// UV sphere (closed), radius r, centre c.
TriMesh rd_sphere(double r, const Vec3& c, int nu = 64, int nv = 32) {
  TriMesh m;
  m.V.resize(2 + nu * (nv - 1), 3);
  m.V.row(0) = (c + Vec3(0, r, 0)).transpose();
  m.V.row(1) = (c - Vec3(0, r, 0)).transpose();
  for (int j = 1; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double th = M_PI * j / nv, ph = 2 * M_PI * i / nu;
      m.V.row(2 + (j - 1) * nu + i) =
          (c + r * Vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph))).transpose();
    }
  std::vector<Eigen::Vector3i> f;
  auto id = [&](int j, int i) { return 2 + (j - 1) * nu + (i % nu); };
  for (int i = 0; i < nu; ++i) {
    f.push_back({0, id(1, i + 1), id(1, i)});
    f.push_back({1, id(nv - 1, i), id(nv - 1, i + 1)});
    for (int j = 1; j + 1 < nv; ++j) {
      f.push_back({id(j, i), id(j, i + 1), id(j + 1, i + 1)});
      f.push_back({id(j, i), id(j + 1, i + 1), id(j + 1, i)});
    }
  }
  m.F.resize(f.size(), 3);
  for (size_t k = 0; k < f.size(); ++k) m.F.row(k) = f[k].transpose();
  return m;
}

bool is_bg(const cv::Vec3b& p) { return p == cv::Vec3b(255, 255, 255); }

}  // namespace

TEST_CASE("render: a sphere is a lit disc of the framed size") {
  const TriMesh s = rd_sphere(0.4, Vec3(0.3, -0.2, 0.1));
  RenderOptions o;
  o.width = o.height = 200;
  o.margin = 0.1;
  const cv::Mat img = render_meshes({s}, {}, o);
  REQUIRE(img.type() == CV_8UC3);
  REQUIRE(img.rows == 200);
  REQUIRE(img.cols == 200);
  int lit = 0;
  double bright_ul = 0, bright_lr = 0;
  int n_ul = 0, n_lr = 0;
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      const double rx = x + 0.5 - 100, ry = y + 0.5 - 100, rr = std::hypot(rx, ry);
      const double R = 100 / 1.1;  // disc radius in pixels: half extent / (1 + margin)
      if (!is_bg(p)) {
        ++lit;
        CHECK(rr < R + 1.5);  // nothing outside the disc
      } else if (rr < R - 2) {
        FAIL_CHECK("background pixel inside the disc at " << x << "," << y);
      }
      const double b = p[0] + p[1] + p[2];
      if (rr < R - 5 && rx < -20 && ry < -20) bright_ul += b, ++n_ul;
      if (rr < R - 5 && rx > 20 && ry > 20) bright_lr += b, ++n_lr;
    }
  const double expected = M_PI / (4 * 1.1 * 1.1);  // pi R^2 / image area
  CHECK(lit / 40000.0 == doctest::Approx(expected).epsilon(0.03));
  // Light from the upper left: that side is brighter.
  REQUIRE(n_ul > 0);
  REQUIRE(n_lr > 0);
  CHECK(bright_ul / n_ul > bright_lr / n_lr + 30);
}

TEST_CASE("render: perspective, colours per mesh, side by side, atomic PNG") {
  const TriMesh a = rd_sphere(0.3, Vec3(-0.5, 0, 0)), b = rd_sphere(0.3, Vec3(0.5, 0, 0));
  RenderOptions o;
  o.width = 240;
  o.height = 120;
  o.perspective = true;
  const cv::Mat img = render_meshes({a, b}, {cv::Vec3b(0, 0, 255), cv::Vec3b(0, 255, 0)}, o);
  // Left sphere red (BGR), right sphere green, at their projected centres.
  const cv::Vec3b l = img.at<cv::Vec3b>(60, 60), r = img.at<cv::Vec3b>(60, 180);
  CHECK(l[2] > 50);
  CHECK(l[1] == 0);
  CHECK(r[1] > 50);
  CHECK(r[2] == 0);
  CHECK(is_bg(img.at<cv::Vec3b>(60, 120)));  // gap between the spheres
  CHECK(is_bg(img.at<cv::Vec3b>(2, 2)));

  const cv::Mat both = side_by_side({img, img}, {"LR", "HR"});
  CHECK(both.cols == 480);
  CHECK(both.rows > 120);

  const std::string dir = std::string(GDSR_BINARY_DIR) + "/test_render_out";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/pair.png";
  write_png_atomic(path, both);
  const cv::Mat back = cv::imread(path);
  REQUIRE_FALSE(back.empty());
  CHECK(cv::norm(back, both, cv::NORM_INF) == 0);
  CHECK_FALSE(std::filesystem::exists(path + ".tmp.png"));
  CHECK_THROWS_AS(write_png_atomic("/nonexistent_dir_xyz/a.png", both), std::runtime_error);
  CHECK_THROWS_AS(render_meshes({}), std::runtime_error);
  TriMesh nan = a;
  nan.V(0, 0) = std::nan("");
  CHECK_THROWS_AS(render_meshes({nan}), std::runtime_error);
}

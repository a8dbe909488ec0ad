// The report folder of gdsr eval on the synthetic waving sheet: tables in the paper's form
// with the figures of the evaluation, plots, LR | GDSR | HR images, and a video OpenCV reads back.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "infer/report.hpp"
#include "infer/report_media.hpp"
#include "infer/report_tables.hpp"
#include "tests/support/data_fixtures.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

TEST_CASE("report: Table 2 steps are 1 50 100 500 and the last that exist") {
  CHECK(gdsr::table_steps(600) == std::vector<int>{1, 50, 100, 500, 600});
  CHECK(gdsr::table_steps(500) == std::vector<int>{1, 50, 100, 500});
  CHECK(gdsr::table_steps(73) == std::vector<int>{1, 50, 73});
  CHECK(gdsr::table_steps(1) == std::vector<int>{1});
}

TEST_CASE("report: tables plots images and video of a short roll-out") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(8);
  gdsr::Prediction p;
  p.first_frame = 1;
  for (int t = 1; t < 8; ++t) {
    gdsr::Points3 g = d.hr_frames[t];
    g.col(2) *= 1.0 + 0.05 * t;  // an error growing over the roll-out
    p.G.push_back(g);
  }
  p.seconds_per_frame = 0.0123;
  const gdsr::Evaluation e = gdsr::evaluate(d, p.G, p.first_frame, 2);
  gdsr_test::TempDir dir("report");
  gdsr::ReportOptions opt;
  opt.dataset_path = "wave_data";
  opt.image_steps = {1, 7};
  const auto files = gdsr::write_eval_report(dir / "r", d, p, e, opt);
  for (const auto& f : files) CHECK(std::filesystem::exists(dir / ("r/" + f)));

  std::ifstream in(dir / "r/report.md");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string md = ss.str();
  for (const char* s : {"## Table 2", "## Table 3", "## Table 4", "## Vertex error", "| 1-step | roll-7 | mean |",
                        "| GDSR | E_u |", "| Upsampled LR | E_uv |", "| HR simulation | E_v |",
                        "images/normals_00007.png", "plots/energies.png", "rollout.avi", "0.012 + -"})
    CHECK_MESSAGE(md.find(s) != std::string::npos, s);
  char row[128];
  std::snprintf(row, sizeof row, "| wave | whole map | %.4f | %.4f | %.4f |", e.mean.ssim_lr, e.mean.ssim,
                e.mean.ssim_scale);
  CHECK(md.find(row) != std::string::npos);
  std::snprintf(row, sizeof row, "| wave | garment only | %.4f | %.4f | %.4f |", e.mean.ssim_garment_lr,
                e.mean.ssim_garment, e.mean.ssim_garment_scale);
  CHECK(md.find(row) != std::string::npos);
  std::snprintf(row, sizeof row, "| HR at the LR scale | %.2f | %.2f | %.2f |", 1e3 * e.frames[0].error_scale,
                1e3 * e.frames[6].error_scale, 1e3 * e.mean.error_scale);
  CHECK(md.find(row) != std::string::npos);
  std::snprintf(row, sizeof row, "| GDSR | %.2f | %.2f | %.2f |", 1e3 * e.frames[0].error, 1e3 * e.frames[6].error,
                1e3 * e.mean.error);
  CHECK(md.find(row) != std::string::npos);
  CHECK(e.frames[6].error > e.frames[0].error);

  // Images: three labelled panels side by side, the shaded one with two views.
  const cv::Mat normals = cv::imread(dir / "r/images/normals_00001.png");
  const cv::Mat shaded = cv::imread(dir / "r/images/shaded_00007.png");
  REQUIRE_FALSE(normals.empty());
  REQUIRE_FALSE(shaded.empty());
  CHECK(normals.cols >= 3 * 400);
  CHECK(shaded.cols >= 3 * 360);
  CHECK(shaded.rows >= 2 * 360);
  const cv::Mat energies = cv::imread(dir / "r/plots/energies.png");
  CHECK(energies.rows == 3 * 280);

  nlohmann::json j;
  std::ifstream(dir / "r/report.json") >> j;
  CHECK(j["per_frame"].size() == 7);
  CHECK(j["per_frame"][2]["ssim"].get<double>() == doctest::Approx(e.frames[2].ssim));
  CHECK(j["per_frame"][2]["ssim_hr_lr_scale"].get<double>() == doctest::Approx(e.frames[2].ssim_scale));
  CHECK(j["per_frame"][2]["ssim_garment_lr"].get<double>() == doctest::Approx(e.frames[2].ssim_garment_lr));
  CHECK(j["mean"]["ssim_garment"].get<double>() == doctest::Approx(e.mean.ssim_garment));
  const cv::Mat ssim_plot = cv::imread(dir / "r/plots/ssim.png");
  CHECK(ssim_plot.rows == 2 * 280);  // whole map above, garment pixels below
  CHECK(j["mean"]["error_hr_lr_scale_m"].get<double>() == doctest::Approx(e.mean.error_scale));
  CHECK_FALSE(j["per_frame"][1].contains("ssim"));  // ssim_every 2

  cv::VideoCapture video(dir / "r/rollout.avi");
  REQUIRE(video.isOpened());
  CHECK(static_cast<int>(video.get(cv::CAP_PROP_FRAME_COUNT)) == 7);
  cv::Mat frame;
  REQUIRE(video.read(frame));
  CHECK(frame.cols >= 3 * 320);

  opt.image_steps = {8};
  CHECK_THROWS_WITH_AS(gdsr::write_eval_report(dir / "r2", d, p, e, opt), doctest::Contains("image step 8"),
                       gdsr::Error);
}

TEST_CASE("report: the error and SSIM plots draw the HR at the LR scale") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(5);
  const gdsr::Evaluation e = gdsr::evaluate(d, {d.hr_frames[1], d.hr_frames[2], d.hr_frames[3]}, 1);
  gdsr::Evaluation moved = e;  // the same evaluation with that series alone changed
  for (auto& f : moved.frames) f.error_scale *= 0.5, f.ssim_scale = 0.5 * (f.ssim_scale + f.ssim_lr);
  CHECK(cv::norm(gdsr::plot_error(e), gdsr::plot_error(moved), cv::NORM_L1) > 0);
  CHECK(cv::norm(gdsr::plot_ssim(e), gdsr::plot_ssim(moved), cv::NORM_L1) > 0);
  gdsr::Evaluation garment_moved = e;  // the garment-pixel panel draws its own series
  for (auto& f : garment_moved.frames) f.ssim_garment_scale = 0.5 * (f.ssim_garment_scale + f.ssim_garment_lr);
  CHECK(cv::norm(gdsr::plot_ssim(e), gdsr::plot_ssim(garment_moved), cv::NORM_L1) > 0);
}

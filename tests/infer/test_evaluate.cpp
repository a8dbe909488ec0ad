// gdsr::evaluate on the synthetic waving sheet: ground truth against itself and the LR baseline.
#include <doctest/doctest.h>

#include "infer/evaluate.hpp"
#include "tests/support/data_fixtures.hpp"

TEST_CASE("evaluate: the ground truth scores error 0 and SSIM 1 / the LR baseline does worse") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(4);
  const gdsr::Evaluation e = gdsr::evaluate(d, {d.hr_frames[1], d.hr_frames[2]}, 1);
  CHECK(e.frames.size() == 2);
  CHECK(e.mean.error == doctest::Approx(0).epsilon(1e-12));
  CHECK(e.mean.ssim == doctest::Approx(1).epsilon(1e-6));
  CHECK(e.mean.error_lr > 1e-4);
  CHECK(e.mean.ssim_lr < 0.999);
  CHECK(e.mean.energies.E_u == doctest::Approx(e.truth.E_u));
  CHECK_THROWS_AS(gdsr::evaluate(d, {d.hr_frames[0]}, 4), std::runtime_error);  // frame out of range
}

TEST_CASE("evaluate: the HR at the LR scale reproduces a flat tilted sheet exactly / misses the wave's ripple") {
  // Barycentric down- and upsampling are exact on positions affine in UV, so the perfect-correction
  // reference equals the truth on a flat sheet, tilted and moved (closed form: error 0, SSIM 1).
  gdsr::Dataset d = gdsr_test::wave_dataset(3);
  const gdsr::Evaluation wave = gdsr::evaluate(d, {d.hr_frames[1], d.hr_frames[2]}, 1);
  CHECK(wave.mean.error_scale > 1e-4);  // the 4 mm ripple along y is finer than the LR grid
  CHECK(wave.mean.ssim_scale < 0.999);
  for (auto& f : d.hr_frames) {
    f = d.hr.V;
    for (int i = 0; i < f.rows(); ++i) f(i, 2) = 0.2 * f(i, 0) - 0.1 * f(i, 1) + 0.05;
  }
  const gdsr::Evaluation flat = gdsr::evaluate(d, {d.hr_frames[1], d.hr_frames[2]}, 1);
  CHECK(flat.mean.error_scale == doctest::Approx(0).epsilon(1e-12));
  CHECK(flat.mean.ssim_scale == doctest::Approx(1).epsilon(1e-6));
  CHECK(flat.mean.error_lr > 1e-3);  // the LR frames still wave
}

TEST_CASE("evaluate: garment-pixel SSIM: the truth scores 1, the LR baseline lower than on the whole map") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(3);
  const gdsr::Evaluation e = gdsr::evaluate(d, {d.hr_frames[1], d.hr_frames[2]}, 1);
  CHECK(e.mean.ssim_garment == doctest::Approx(1).epsilon(1e-6));
  CHECK(e.mean.ssim_garment_lr < e.mean.ssim_lr);  // the background dilutes the difference
  CHECK(e.frames[0].ssim_garment_scale < 0.999);
  const cv::Mat mask = gdsr::garment_mask(d.raster);
  int garment = 0;
  for (size_t p = 0; p < d.raster.tri.size(); ++p) garment += d.raster.tri[p] >= 0;
  CHECK(cv::countNonZero(mask) == garment);
  CHECK(garment < d.raster.width * d.raster.height);
}

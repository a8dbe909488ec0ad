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

#include <doctest/doctest.h>

#include "gdsr/data/dataset_compare.hpp"
#include "gdsr/error.hpp"

using gdsr::Points3;

TEST_CASE("dataset compare: per-frame mean distance, largest vertex, bit-identity and bad counts") {
  const Points3 a = Points3::Random(50, 3);
  Points3 b = a;
  b.col(0).array() += 0.003;      // every vertex 3 mm along x
  Points3 c = a;
  c(7, 2) += 0.04;                // one vertex 40 mm along z
  const gdsr::FrameDifference same = gdsr::frame_difference({a, a}, {a, a}, "x");
  CHECK(same.identical);
  CHECK(same.clip_mean() == 0);
  const gdsr::FrameDifference d = gdsr::frame_difference({a, a}, {b, c}, "x");
  CHECK_FALSE(d.identical);
  CHECK(d.mean[0] == doctest::Approx(0.003).epsilon(1e-9));
  CHECK(d.mean[1] == doctest::Approx(0.04 / 50).epsilon(1e-9));
  CHECK(d.max == doctest::Approx(0.04).epsilon(1e-9));
  CHECK(d.worst_frame() == 0);
  CHECK(d.clip_mean() == doctest::Approx((0.003 + 0.04 / 50) / 2).epsilon(1e-9));
  CHECK_THROWS_AS(gdsr::frame_difference({a}, {a, a}, "x"), gdsr::Error);
  CHECK_THROWS_AS(gdsr::frame_difference({a}, {Points3(a.topRows(49))}, "x"), gdsr::Error);
  CHECK(gdsr::frame_difference({}, {}, "x").worst_frame() == -1);
}

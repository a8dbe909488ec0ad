// PC2 point cache read back by a reader written here from the format's description.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "gdsr/io/point_cache.hpp"
#include "tests/support/data_fixtures.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

TEST_CASE("point cache: PC2 header and samples read back") {
  std::vector<gdsr::Points3> frames;
  for (int t = 0; t < 4; ++t) {
    gdsr::Points3 V(7, 3);
    for (int i = 0; i < 7; ++i) V.row(i) << 0.1 * i, 0.01 * t * i, std::sin(i + t);
    frames.push_back(V);
  }
  gdsr_test::TempDir dir("pc2");
  gdsr::write_pc2(dir / "a.pc2", frames, 3.0f, 1.0f);
  std::ifstream in(dir / "a.pc2", std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string b = ss.str();
  REQUIRE(b.size() == 32 + 4 * 7 * 3 * 4);
  CHECK(std::memcmp(b.data(), "POINTCACHE2\0", 12) == 0);
  int32_t version, points, samples;
  float start, rate;
  std::memcpy(&version, b.data() + 12, 4);
  std::memcpy(&points, b.data() + 16, 4);
  std::memcpy(&start, b.data() + 20, 4);
  std::memcpy(&rate, b.data() + 24, 4);
  std::memcpy(&samples, b.data() + 28, 4);
  CHECK(version == 1);
  CHECK(points == 7);
  CHECK(start == 3.0f);
  CHECK(rate == 1.0f);
  CHECK(samples == 4);
  for (int t : {0, 3})
    for (int i : {0, 6})
      for (int c = 0; c < 3; ++c) {
        float x;
        std::memcpy(&x, b.data() + 32 + 4 * ((t * 7 + i) * 3 + c), 4);
        CHECK(x == doctest::Approx(frames[t](i, c)).epsilon(1e-6));
      }
  CHECK_THROWS_WITH_AS(gdsr::write_pc2(dir / "b.pc2", {frames[0], frames[1].topRows(2)}),
                       doctest::Contains("frame 1 has 2 vertices"), gdsr::Error);
  CHECK_THROWS_AS(gdsr::write_pc2(dir / "b.pc2", {}), gdsr::Error);
  CHECK_FALSE(std::filesystem::exists(dir / "b.pc2"));
}

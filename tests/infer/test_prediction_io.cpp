// The prediction folder of gdsr infer: written and read back, and a broken folder named in
// the error.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "infer/prediction_io.hpp"
#include "tests/support/data_fixtures.hpp"

#include <fstream>

TEST_CASE("prediction io: round trip and errors naming the file") {
  gdsr::Prediction p;
  p.first_frame = 3;
  p.G = {gdsr::Points3::Random(5, 3), gdsr::Points3::Random(5, 3)};
  p.C_hat = {gdsr::Points3::Random(2, 3), gdsr::Points3::Random(2, 3)};
  p.model = "m.ckpt";
  p.seconds_per_frame = 0.25;
  gdsr_test::TempDir dir("prediction_io");
  gdsr::write_prediction(dir / "p", p);
  const gdsr::Prediction q = gdsr::read_prediction(dir / "p");
  CHECK(q.first_frame == 3);
  REQUIRE(q.G.size() == 2);
  CHECK((q.G[1] - p.G[1]).cwiseAbs().maxCoeff() < 1e-6);  // float32 on disk
  CHECK(q.C_hat.size() == 2);
  CHECK(q.model == "m.ckpt");
  CHECK(q.seconds_per_frame == 0.25);
  CHECK(gdsr::read_prediction(dir / "p", true).C_hat.empty());

  std::ofstream(dir / "p/prediction.json", std::ios::trunc) << "{\"frames\": 2}";
  CHECK_THROWS_WITH_AS(gdsr::read_prediction(dir / "p"), doctest::Contains("prediction.json"), gdsr::Error);
  CHECK_THROWS_WITH_AS(gdsr::read_prediction(dir / "none"), doctest::Contains("not a folder written by gdsr infer"),
                       gdsr::Error);
}

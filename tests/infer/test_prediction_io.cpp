// The prediction folder of gdsr infer: written and read back, and a broken folder named in
// the error.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "infer/prediction_io.hpp"
#include "tests/support/data_fixtures.hpp"

#include "gdsr/data/dataset.hpp"

#include <cmath>
#include <filesystem>
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

TEST_CASE("prediction io: an interrupted write leaves no prediction.json and mixed files are refused") {
  namespace fs = std::filesystem;
  gdsr::Prediction p;
  p.first_frame = 1;
  p.G = {gdsr::Points3::Random(5, 3), gdsr::Points3::Random(5, 3), gdsr::Points3::Random(5, 3)};
  p.C_hat = {gdsr::Points3::Random(2, 3), gdsr::Points3::Random(2, 3), gdsr::Points3::Random(2, 3)};
  gdsr_test::TempDir dir("prediction_io_commit");
  gdsr::write_prediction(dir / "p", p);
  REQUIRE(fs::exists(dir / "p/prediction.json"));

  // A second write that fails after pred_hr.bin (pred_lr.bin cannot be written): the old
  // prediction.json must not stay beside the new pred_hr.bin.
  fs::remove(dir / "p/pred_lr.bin");
  fs::create_directories(dir / "p/pred_lr.bin/blocker");
  gdsr::Prediction shorter = p;
  shorter.G.pop_back();
  shorter.C_hat.pop_back();
  CHECK_THROWS(gdsr::write_prediction(dir / "p", shorter));
  CHECK_FALSE(fs::exists(dir / "p/prediction.json"));
  CHECK_THROWS_WITH_AS(gdsr::read_prediction(dir / "p", true), doctest::Contains("prediction.json"), gdsr::Error);

  // Arrays of another run than prediction.json, and NaN positions, are refused naming the file.
  fs::remove_all(dir / "p/pred_lr.bin");
  gdsr::write_prediction(dir / "p", p);
  gdsr::write_array(dir / "p/pred_hr.bin", gdsr::frames_to_array(shorter.G));
  CHECK_THROWS_WITH_AS(gdsr::read_prediction(dir / "p", true), doctest::Contains("records 3"), gdsr::Error);
  p.G[2](4, 1) = std::nan("");
  gdsr::write_prediction(dir / "p", p);
  CHECK_THROWS_WITH_AS(gdsr::read_prediction(dir / "p", true), doctest::Contains("pred_hr.bin: frame 2 holds NaN"),
                       gdsr::Error);
}

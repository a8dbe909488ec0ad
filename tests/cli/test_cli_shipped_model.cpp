// The trained models shipped in models/ (models/README.md) as a new user meets them: our
// simulator makes a clip of a motion they never saw (CMU 01_03, 1 s or 0.5 s; both were trained on
// 01_01 and salsa clips, the five-garment one on walk 131_02 too), `gdsr infer` rolls the
// shipped weights out over it with the collision post-process, and `gdsr eval` scores the
// result against the HR simulation.
#include "tests/support/cli_run.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

using gdsr_test::gdsr_run;
using gdsr_test::slurp;
using gdsr_test::TempDir;

TEST_CASE("cli shipped model: on an unseen motion it beats the upsampled LR, stable and unstretched") {
  const std::string bvh = "/usr/share/assimp/models/BVH/01_03.bvh";
  REQUIRE(std::filesystem::exists(bvh));
  const std::string model = std::string(GDSR_SOURCE_DIR) + "/models/gdsr_small_skirt.ckpt";
  REQUIRE(std::filesystem::exists(model));
  TempDir dir("cli_shipped_model");
  REQUIRE(gdsr_run(dir, "data make --garment skirt_short --motion " + bvh + " --start 1 --seconds 1 --out '" +
                            (dir / "ds") + "'")
              .status == 0);
  const gdsr_test::Run infer =
      gdsr_run(dir, "infer --model '" + model + "' --data '" + (dir / "ds") + "' --out '" + (dir / "pred") + "'");
  REQUIRE(infer.status == 0);
  const gdsr_test::Run eval = gdsr_run(dir, "eval --pred '" + (dir / "pred") + "' --data '" + (dir / "ds") +
                                                "' --report '" + (dir / "report") + "' --no-video --no-export");
  REQUIRE(eval.status == 0);
  const nlohmann::json r = nlohmann::json::parse(slurp(dir / "report/report.json"));
  const nlohmann::json& m = r.at("mean");
  const double err = m.at("error_m"), up = m.at("error_lr_m");
  MESSAGE("vertex error " << 1000 * err << " mm, upsampled LR " << 1000 * up << " mm; SSIM " << m.at("ssim").get<double>()
                          << " vs " << m.at("ssim_lr").get<double>() << "; E_u " << m.at("energies").at("E_u").get<double>());
  REQUIRE(std::isfinite(err));
  CHECK(err < 0.88 * up);  // 0.85x on this 1 s clip, 0.84x on the whole 2 s one (models/README.md; revision 32)
  CHECK(m.at("ssim").get<double>() > m.at("ssim_lr").get<double>());
  // Over the garment's pixels (the whole UV map is 85% background, SSIM 1 in both): issue #12's
  // +0.05: +0.058 on this 1 s clip (0.820 / 0.762), +0.058 on the 2 s one (0.840 / 0.782; solver
  // revision 32).
  const double garment = m.at("ssim_garment"), garment_lr = m.at("ssim_garment_lr");
  MESSAGE("garment-pixel SSIM " << garment << " vs " << garment_lr);
  CHECK(garment > garment_lr + 0.05);
  CHECK(eval.out.find("garment pixels  GDSR") != std::string::npos);
  for (const auto& f : r.at("per_frame")) {                // every frame, not only the mean
    CHECK(f.at("energies").at("E_u").get<double>() < 0.04);  // the paper's range: 0.01-0.04
    CHECK(f.at("energies").at("E_uv").get<double>() < 0.065);
  }
  // The paper's body pass (each HR vertex pushed out of its LR vertex's tangent plane) moves
  // more HR vertices than the default, each out of its own plane.
  const gdsr_test::Run paper = gdsr_run(dir, "infer --model '" + model + "' --data '" + (dir / "ds") +
                                                 "' --lr-planes --out '" + (dir / "pred_paper") + "'");
  REQUIRE(paper.status == 0);
  const auto moved = [](const std::string& out) {
    const size_t at = out.find(" HR vertices moved by collision handling");
    REQUIRE(at != std::string::npos);
    return std::stol(out.substr(out.rfind(", ", at) + 2));
  };
  MESSAGE("HR vertices moved: " << moved(infer.out) << " (own planes), " << moved(paper.out) << " (the paper's)");
  CHECK(moved(infer.out) > 0);
  CHECK(moved(paper.out) > moved(infer.out));
  // Given the HR simulation as its history (--true-history) this model scores what it scores on
  // its own history, within 2%: it does not use its history (models/README.md, "Training through
  // the roll-out"). The report names the run.
  const gdsr_test::Run taught =
      gdsr_run(dir, "eval --model '" + model + "' --data '" + (dir / "ds") + "' --true-history --report '" +
                        (dir / "taught") + "' --no-video --no-export");
  REQUIRE(taught.status == 0);
  const nlohmann::json t = nlohmann::json::parse(slurp(dir / "taught/report.json"));
  const double err_taught = t.at("mean").at("error_m");
  MESSAGE("vertex error with the true history " << 1000 * err_taught << " mm, own " << 1000 * err << " mm");
  CHECK(t.at("model").get<std::string>().find("(true history)") != std::string::npos);
  CHECK(std::abs(err_taught - err) < 0.02 * err);
  CHECK(err_taught != err);  // another history, another output
}

TEST_CASE("cli shipped model: the five-garment model beats the upsampled LR on pants in an unseen motion") {
  // models/gdsr_small_paper5.ckpt never saw CMU 01_03; pants are one of its five garments. Half a
  // second: the 10 mm pants simulate at 2.4 s a frame on one core (1 s took 270 s in CI).
  const std::string bvh = "/usr/share/assimp/models/BVH/01_03.bvh";
  REQUIRE(std::filesystem::exists(bvh));
  const std::string model = std::string(GDSR_SOURCE_DIR) + "/models/gdsr_small_paper5.ckpt";
  TempDir dir("cli_shipped_paper5");
  REQUIRE(gdsr_run(dir, "data make --garment pants --motion " + bvh + " --start 1 --seconds 0.5 --out '" +
                            (dir / "ds") + "'")
              .status == 0);
  REQUIRE(gdsr_run(dir, "infer --model '" + model + "' --data '" + (dir / "ds") + "' --out '" + (dir / "pred") + "'")
              .status == 0);
  REQUIRE(gdsr_run(dir, "eval --pred '" + (dir / "pred") + "' --data '" + (dir / "ds") + "' --report '" +
                            (dir / "report") + "' --no-video --no-export")
              .status == 0);
  const nlohmann::json r = nlohmann::json::parse(slurp(dir / "report/report.json"));
  const nlohmann::json& m = r.at("mean");
  const double err = m.at("error_m"), up = m.at("error_lr_m");
  MESSAGE("pants, 01_03: vertex error " << 1000 * err << " mm, upsampled LR " << 1000 * up << " mm; SSIM "
                                        << m.at("ssim").get<double>() << " vs " << m.at("ssim_lr").get<double>());
  REQUIRE(std::isfinite(err));
  CHECK(err < 0.92 * up);  // 0.86x (5.15 against 6.01 mm; 5.31 / 6.22 before the crotch arc, revision 25)
  CHECK(m.at("ssim").get<double>() > m.at("ssim_lr").get<double>());
  for (const auto& f : r.at("per_frame")) {
    CHECK(f.at("energies").at("E_u").get<double>() < 0.04);  // the paper's range: 0.01-0.04
    CHECK(f.at("energies").at("E_uv").get<double>() < 0.065);
  }
}

TEST_CASE("cli shipped model: the layer pass keeps an outer layer at the dataset's layer gap, or --layer-offset") {
  // A coarse two-layer dress (0.1 s, 80 / 60 mm): the roll-out's collision pass pairs each outer
  // vertex with the layer under it. By default it keeps the outer layer the simulation's own 4 mm
  // off (manifest layer_gap_m); the paper's 20 mm moves more of it.
  TempDir dir("cli_layer_offset");
  const std::string model = std::string(GDSR_SOURCE_DIR) + "/models/gdsr_small_paper5.ckpt";
  REQUIRE(
      gdsr_run(dir, "data make --garment dress_layered --seconds 0.1 --lr-pd 0.08 --hr-pd 0.06 --raster 64 --out '" +
                        (dir / "ds") + "'")
          .status == 0);
  const auto moved = [](const std::string& out) {
    const size_t at = out.find(" HR vertices moved by collision handling");
    REQUIRE(at != std::string::npos);
    return std::stol(out.substr(out.rfind(", ", at) + 2));
  };
  const gdsr_test::Run own =
      gdsr_run(dir, "infer --model '" + model + "' --data '" + (dir / "ds") + "' --out '" + (dir / "own") + "'");
  REQUIRE(own.status == 0);
  CHECK(own.out.find("layer offset 4.0 mm") != std::string::npos);
  const gdsr_test::Run paper = gdsr_run(dir, "infer --model '" + model + "' --data '" + (dir / "ds") +
                                                 "' --layer-offset 0.02 --out '" + (dir / "paper") + "'");
  REQUIRE(paper.status == 0);
  CHECK(paper.out.find("layer offset 20.0 mm") != std::string::npos);
  MESSAGE("HR vertices moved: " << moved(own.out) << " at 4 mm, " << moved(paper.out) << " at 20 mm");
  CHECK(moved(paper.out) > moved(own.out));
}

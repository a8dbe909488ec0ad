// gdsr export and gdsr eval --report on a small dataset and a prediction folder written
// here: the files appear, and bad flags give a one-line error.
#include "gdsr/geometry/obj_io.hpp"
#include "tests/support/cli_run.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <filesystem>

using gdsr_test::check_one_line_error;
using gdsr_test::gdsr_run;
using gdsr_test::Run;
using gdsr_test::TempDir;
namespace fs = std::filesystem;

namespace {

// The waving-sheet dataset in dir/ds and a "prediction" of its frames 2..5 in dir/pred.
void write_inputs(const TempDir& dir) {
  const gdsr::Dataset d = gdsr_test::wave_dataset(6);
  gdsr::write_dataset(dir / "ds", d);
  fs::create_directories(dir / "pred");
  std::vector<gdsr::Points3> G(d.hr_frames.begin() + 2, d.hr_frames.end());
  for (auto& g : G) g.col(2) *= 1.1;
  gdsr::write_array(dir / "pred/pred_hr.bin", gdsr::frames_to_array(G));
  gdsr::write_file_atomic(dir / "pred/prediction.json", nlohmann::json{{"first_frame", 2}, {"frames", 4}}.dump());
}

}  // namespace

TEST_CASE("cli export: glTF PC2 and OBJ of the three sequences") {
  TempDir dir("cli_export");
  write_inputs(dir);
  const Run r = gdsr_run(dir, "export --pred '" + (dir / "pred") + "' --data '" + (dir / "ds") + "' --out '" +
                                  (dir / "exp") + "' --obj-every 3");
  CAPTURE(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("frames 2..5") != std::string::npos);
  for (const char* f : {"export.json", "gdsr.gltf", "gdsr.bin", "gdsr.pc2", "gdsr_rest.obj", "lr.gltf", "hr.pc2",
                        "obj/gdsr_00002.obj", "obj/gdsr_00005.obj", "obj/lr_00005.obj"})
    CHECK_MESSAGE(fs::exists(dir / ("exp/" + std::string(f))), f);
  CHECK_FALSE(fs::exists(dir / "exp/obj/gdsr_00003.obj"));

  const Run only = gdsr_run(dir, "export --pred '" + (dir / "pred") + "' --data '" + (dir / "ds") + "' --out '" +
                                     (dir / "exp2") + "' --formats gltf --sequences gdsr");
  REQUIRE(only.status == 0);
  CHECK(fs::exists(dir / "exp2/gdsr.gltf"));
  CHECK_FALSE(fs::exists(dir / "exp2/lr.gltf"));
  CHECK_FALSE(fs::exists(dir / "exp2/obj"));

  const std::string base =
      "export --pred '" + (dir / "pred") + "' --data '" + (dir / "ds") + "' --out '" + (dir / "bad");
  check_one_line_error(gdsr_run(dir, base + "' --formats gltf,fbx"), "--formats: unknown name 'fbx'");
  check_one_line_error(gdsr_run(dir, base + "' --sequences gdsr,truth"), "--sequences: unknown name 'truth'");
  check_one_line_error(gdsr_run(dir, base + "' --obj-every 0"), "--obj-every");
  check_one_line_error(gdsr_run(dir, "export --pred '" + (dir / "nothing") + "' --data '" + (dir / "ds") + "'"),
                       "prediction.json");
  CHECK_FALSE(fs::exists(dir / "bad"));
}

TEST_CASE("cli eval: --report writes tables plots images video and exports") {
  TempDir dir("cli_report");
  write_inputs(dir);
  const Run r = gdsr_run(dir, "eval --pred '" + (dir / "pred") + "' --data '" + (dir / "ds") + "' --report '" +
                                  (dir / "rep") + "' --report-steps 1,4");
  CAPTURE(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("evaluation over 4 frames") != std::string::npos);
  CHECK(r.out.find("wrote report") != std::string::npos);
  for (const char* f : {"report.md", "report.json", "plots/error.png", "plots/ssim.png", "plots/energies.png",
                        "images/normals_00001.png", "images/shaded_00004.png", "rollout.avi", "export/gdsr.gltf",
                        "export/hr.pc2", "export/export.json"})
    CHECK_MESSAGE(fs::exists(dir / ("rep/" + std::string(f))), f);
  CHECK(gdsr_test::slurp(dir / "rep/report.md").find("## Exports") != std::string::npos);
  // The viewer when three.js is installed (scripts/setup.sh), else a note saying why not.
  const bool three = fs::exists(std::string(GDSR_SOURCE_DIR) + "/viewer/node_modules/three/build/three.module.js");
  CHECK(fs::exists(dir / "rep/viewer/index.html") == three);
  CHECK(fs::exists(dir / "rep/viewer/three/three.module.js") == three);
  if (!three) CHECK(r.err.find("no viewer in the report") != std::string::npos);
  check_one_line_error(gdsr_run(dir, "eval --pred '" + (dir / "pred") + "' --data '" + (dir / "ds") + "' --report '" +
                                         (dir / "rep2") + "' --report-steps 9"),
                       "image step 9");
  check_one_line_error(gdsr_run(dir, "eval --pred '" + (dir / "pred") + "' --data '" + (dir / "ds") + "' --report '" +
                                         (dir / "rep2") + "' --video-every 0"),
                       "--video-every");
}

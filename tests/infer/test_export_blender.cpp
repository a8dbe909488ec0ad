// A real client opens the exports: Debian's Blender, in background mode, imports the glTF
// (glTF add-on), one OBJ per frame (OBJ importer) and the PC2 point cache on the rest OBJ
// (Mesh Cache modifier) written by export_rollout, and reports vertex counts and positions
// at a few frames (tests/support/blender_read_exports.py). When Blender is not installed
// the test says "SKIPPED" (ctest reports it as skipped); scripts/setup.sh installs it.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "infer/export_rollout.hpp"
#include "tests/support/data_fixtures.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace {

std::string find_blender() {
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "");
  for (std::string dir; std::getline(ss, dir, ':');)
    if (!dir.empty() && ::access((dir + "/blender").c_str(), X_OK) == 0) return dir + "/blender";
  return "";
}

// Largest distance between Blender's vertex i and the expected position of vertex i.
double worst_distance(const nlohmann::json& pts, const gdsr::Points3& expected, const std::vector<int>* map) {
  double worst = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const int v = map ? (*map)[i] : static_cast<int>(i);
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(pts[i][c].get<double>() - expected(v, c)));
  }
  return worst;
}

}  // namespace

TEST_CASE("export blender: Blender imports the glTF and OBJ and plays the PC2 with the right positions") {
  const std::string blender = find_blender();
  if (blender.empty()) {
    MESSAGE("SKIPPED: blender is not installed (apt-get install blender, or run scripts/setup.sh)");
    WARN_MESSAGE(false, "the Blender import test did not run");
    return;
  }
  const gdsr::Dataset d = gdsr_test::wave_dataset(6);
  std::vector<gdsr::Points3> G;
  for (int t = 0; t < 5; ++t) G.push_back(d.hr_frames[t] + gdsr::Points3::Constant(d.hr_frames[t].rows(), 3, 0.01 * t));
  gdsr_test::TempDir dir("export_blender");
  gdsr::RolloutExportOptions opt;
  opt.lr = opt.hr = false;
  gdsr::export_rollout(dir / "exp", d, G, 0, opt);

  const std::string out = dir / "blender.json", log = dir / "blender.log";
  const std::string cmd = "'" + blender + "' -b --factory-startup --python '" + GDSR_SOURCE_DIR +
                          "/tests/support/blender_read_exports.py' -- '" + out + "' " +
                          std::to_string(static_cast<int>(d.manifest.fps)) + " 0,2,4 'gltf=" + (dir / "exp/gdsr.gltf") +
                          "' 'obj=" + (dir / "exp/obj/gdsr_#####.obj") + "' 'pc2=" + (dir / "exp/gdsr_rest.obj") + "," +
                          (dir / "exp/gdsr.pc2") + "' >'" + log + "' 2>&1";
  const int rc = std::system(cmd.c_str());
  std::ifstream in(out);
  if (!in || !WIFEXITED(rc) || WEXITSTATUS(rc) != 0) {
    std::ifstream l(log);
    std::stringstream ss;
    ss << l.rdbuf();
    FAIL("blender failed (status " << rc << "):\n" << ss.str());
  }
  const nlohmann::json r = nlohmann::json::parse(in);
  REQUIRE(r.size() == 3);
  const auto& gltf = r[0];
  const auto& obj = r[1];
  const auto& pc2 = r[2];
  CHECK(gltf["vertices"] == d.hr.UV.rows());  // one glTF vertex per UV vertex
  CHECK(obj["vertices"] == d.hr.V.rows());
  CHECK(pc2["vertices"] == d.hr.V.rows());
  for (int k : {0, 2, 4}) {
    const std::string key = std::to_string(k);
    CAPTURE(k);
    CHECK(worst_distance(gltf["frames"][key], G[k], &d.hr.uv_to_vertex) < 1e-5);  // float32 and shape-key sums
    CHECK(worst_distance(obj["frames"][key], G[k], nullptr) < 1e-6);
    CHECK(worst_distance(pc2["frames"][key], G[k], nullptr) < 1e-6);
  }
  // The frames differ: a wrong frame would fail the checks above.
  CHECK(worst_distance(gltf["frames"]["4"], G[2], &d.hr.uv_to_vertex) > 1e-3);
}

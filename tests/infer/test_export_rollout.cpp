// gdsr::export_rollout on the synthetic waving sheet: export.json lists what was written,
// the per-frame OBJs (read here line by line) hold the right frames, the PC2 holds the
// welded vertices of the rest OBJ, and the HR glTF texcoords follow the UV raster.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "infer/export_rollout.hpp"
#include "tests/support/data_fixtures.hpp"

#include <array>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

namespace {

// The "v" lines of an OBJ.
std::vector<std::array<double, 3>> obj_vertices(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in);
  std::vector<std::array<double, 3>> v;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("v ", 0) == 0) {
      std::istringstream ss(line.substr(2));
      std::array<double, 3> p{};
      ss >> p[0] >> p[1] >> p[2];
      v.push_back(p);
    }
  return v;
}

}  // namespace

TEST_CASE("export rollout: gdsr lr hr sequences with OBJ per frame PC2 and glTF listed in export.json") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(6);
  std::vector<gdsr::Points3> G;
  for (int t = 1; t < 5; ++t) G.push_back(d.hr_frames[t] * 1.01);  // a "prediction" of frames 1..4
  gdsr_test::TempDir dir("export_rollout");
  gdsr::RolloutExportOptions opt;
  opt.formats.obj_every = 2;
  const nlohmann::json j = gdsr::export_rollout(dir / "out", d, G, 1, opt);

  std::ifstream in(dir / "out/export.json");
  REQUIRE(in);
  CHECK(nlohmann::json::parse(in) == j);
  CHECK(j["first_frame"] == 1);
  CHECK(j["frames"] == 4);
  REQUIRE(j["sequences"].size() == 3);
  std::map<std::string, nlohmann::json> seq;
  for (const auto& s : j["sequences"]) seq[s["name"]] = s;
  CHECK(seq["lr"]["vertices"] == d.lr.V.rows());
  CHECK(seq["gdsr"]["vertices"] == d.hr.V.rows());
  REQUIRE(seq["gdsr"]["obj"].size() == 2);  // steps 0 and 2: dataset frames 1 and 3
  CHECK(seq["gdsr"]["obj"][1] == "obj/gdsr_00003.obj");
  for (const auto& s : j["sequences"])
    for (const char* key : {"gltf", "gltf_buffer", "pc2", "rest_obj"})
      CHECK(std::filesystem::exists(dir / ("out/" + s[key].get<std::string>())));

  // OBJ of dataset frame 3: the prediction G[2] and the HR simulation frame 3.
  const auto pred = obj_vertices(dir / "out/obj/gdsr_00003.obj");
  const auto truth = obj_vertices(dir / "out/obj/hr_00003.obj");
  REQUIRE(pred.size() == static_cast<size_t>(d.hr.V.rows()));
  for (int i : {0, 17, 80})
    for (int c = 0; c < 3; ++c) {
      CHECK(pred[i][c] == doctest::Approx(G[2](i, c)).epsilon(1e-7));
      CHECK(truth[i][c] == doctest::Approx(d.hr_frames[3](i, c)).epsilon(1e-7));
    }

  // PC2 of lr: one sample per exported frame over the rest OBJ's welded vertices.
  std::ifstream pc(dir / "out/lr.pc2", std::ios::binary);
  std::stringstream ss;
  ss << pc.rdbuf();
  const std::string b = ss.str();
  int32_t points = 0, samples = 0;
  std::memcpy(&points, b.data() + 16, 4);
  std::memcpy(&samples, b.data() + 28, 4);
  CHECK(points == static_cast<int32_t>(obj_vertices(dir / "out/lr_rest.obj").size()));
  CHECK(samples == 4);
  float x = 0;
  std::memcpy(&x, b.data() + 32 + 4 * ((3 * points + 5) * 3 + 2), 4);  // sample 3, vertex 5, z
  CHECK(x == doctest::Approx(d.lr_frames[4](5, 2)).epsilon(1e-6));

  // HR texcoords: the raster pixel of each UV vertex over the image size.
  const gdsr::Points2 tc = gdsr::raster_texcoords(d.raster, d.hr.UV);
  const gdsr::Vec2 px = d.raster.uv_to_pixel(d.hr.UV.row(7).transpose());
  CHECK(tc(7, 0) * d.raster.width == doctest::Approx(px.x()));
  CHECK(tc(7, 1) * d.raster.height == doctest::Approx(px.y()));

  CHECK_THROWS_WITH_AS(gdsr::export_rollout(dir / "bad", d, G, 3), doctest::Contains("outside the dataset's 6 frames"),
                       gdsr::Error);
}

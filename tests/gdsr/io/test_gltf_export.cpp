// glTF export read back by a parser written here from the glTF 2.0 specification (JSON
// structure, accessors into the .bin buffer, morph targets and the weights animation): the
// positions at a few frames equal the exported frames, float32 rounding aside.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "gdsr/io/gltf_export.hpp"
#include "tests/support/data_fixtures.hpp"
#include "tests/support/grid_garment.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The floats (or uint32 as float) of accessor `a`, checking its view lies inside the buffer.
std::vector<double> read_accessor(const nlohmann::json& g, const std::string& bin, int a, int comps) {
  const auto& acc = g["accessors"][a];
  const auto& view = g["bufferViews"][acc["bufferView"].get<int>()];
  const size_t count = acc["count"], offset = view["byteOffset"], length = view["byteLength"];
  REQUIRE(offset + length <= bin.size());
  REQUIRE(count * comps * 4 == length);
  std::vector<double> out(count * comps);
  for (size_t i = 0; i < out.size(); ++i) {
    if (acc["componentType"] == 5126) {
      float f;
      std::memcpy(&f, bin.data() + offset + 4 * i, 4);
      out[i] = f;
    } else {
      REQUIRE(acc["componentType"] == 5125);
      uint32_t u;
      std::memcpy(&u, bin.data() + offset + 4 * i, 4);
      out[i] = u;
    }
  }
  return out;
}

// A tube with a UV seam, 5 frames of a travelling wave.
std::vector<gdsr::Points3> wave_frames(const gdsr::GarmentMesh& m, int T) {
  std::vector<gdsr::Points3> frames;
  for (int t = 0; t < T; ++t) {
    gdsr::Points3 V = m.V;
    for (int i = 0; i < V.rows(); ++i) V(i, 1) += 0.02 * std::sin(8 * V(i, 0) + 0.7 * t) + 0.001 * t;
    frames.push_back(V);
  }
  return frames;
}

}  // namespace

TEST_CASE("gltf export: structure and accessor counts and positions at frames 0 2 4") {
  const gdsr::GarmentMesh m = gdsr_test::grid_garment(gdsr_test::GridSpec(8, 3, 0.9, 0.3).tube());
  REQUIRE(m.UV.rows() > m.V.rows());  // the seam splits vertices in glTF
  const int T = 5;
  const auto frames = wave_frames(m, T);
  gdsr_test::TempDir dir("gltf_export");
  gdsr::GltfOptions opt;
  opt.fps = 25;
  opt.name = "tube";
  gdsr::write_gltf_sequence(dir / "tube.gltf", m, frames, opt);

  const nlohmann::json g = nlohmann::json::parse(slurp(dir / "tube.gltf"));
  const std::string bin = slurp(dir / "tube.bin");
  CHECK(g["asset"]["version"] == "2.0");
  REQUIRE(g["buffers"].size() == 1);
  CHECK(g["buffers"][0]["uri"] == "tube.bin");
  CHECK(g["buffers"][0]["byteLength"].get<size_t>() == bin.size());
  REQUIRE(g["meshes"].size() == 1);
  CHECK(g["nodes"][0]["mesh"] == 0);
  CHECK(g["scenes"][g["scene"].get<int>()]["nodes"][0] == 0);
  const auto& prim = g["meshes"][0]["primitives"][0];
  const int nuv = static_cast<int>(m.UV.rows());
  CHECK(g["accessors"][prim["attributes"]["POSITION"].get<int>()]["count"] == nuv);
  CHECK(g["accessors"][prim["attributes"]["TEXCOORD_0"].get<int>()]["count"] == nuv);
  CHECK(g["accessors"][prim["indices"].get<int>()]["count"] == 3 * m.F.rows());
  REQUIRE(prim["targets"].size() == T - 1);
  CHECK(g["meshes"][0]["extras"]["targetNames"][1] == "frame_00002");
  CHECK(g["materials"][prim["material"].get<int>()]["doubleSided"] == true);

  // Indices reference the split vertices; texcoords lie in [0, 1].
  const auto idx = read_accessor(g, bin, prim["indices"], 1);
  for (int f = 0; f < m.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) CHECK(idx[3 * f + c] == m.FUV(f, c));
  const auto tc = read_accessor(g, bin, prim["attributes"]["TEXCOORD_0"], 2);
  for (double x : tc) CHECK((x >= 0 && x <= 1));

  // The weights animation: keyframe times k / fps, LINEAR, one weight per target per key.
  REQUIRE(g["animations"].size() == 1);
  const auto& anim = g["animations"][0];
  CHECK(anim["channels"][0]["target"]["path"] == "weights");
  CHECK(anim["channels"][0]["target"]["node"] == 0);
  const auto& sampler = anim["samplers"][anim["channels"][0]["sampler"].get<int>()];
  CHECK(sampler["interpolation"] == "LINEAR");
  const auto times = read_accessor(g, bin, sampler["input"], 1);
  const auto weights = read_accessor(g, bin, sampler["output"], 1);
  REQUIRE(times.size() == T);
  REQUIRE(weights.size() == T * (T - 1));
  CHECK(times[3] == doctest::Approx(3.0 / 25));
  CHECK(g["accessors"][sampler["input"].get<int>()]["max"][0].get<double>() == doctest::Approx(4.0 / 25));

  // Positions at keyframe k: base + sum_j w_j(k) target_j, vertex i at V[uv_to_vertex[i]].
  const auto base = read_accessor(g, bin, prim["attributes"]["POSITION"], 3);
  std::vector<std::vector<double>> targets;
  for (const auto& t : prim["targets"]) {
    const auto& acc = g["accessors"][t["POSITION"].get<int>()];
    CHECK(acc.contains("min"));  // required on POSITION accessors
    targets.push_back(read_accessor(g, bin, t["POSITION"], 3));
  }
  for (int k : {0, 2, 4}) {
    double worst = 0;
    for (int i = 0; i < nuv; ++i)
      for (int c = 0; c < 3; ++c) {
        double x = base[3 * i + c];
        for (int j = 0; j < T - 1; ++j) x += weights[k * (T - 1) + j] * targets[j][3 * i + c];
        worst = std::max(worst, std::abs(x - frames[k](m.uv_to_vertex[i], c)));
      }
    CHECK(worst < 1e-6);  // float32 of positions below 1 m
  }
}

TEST_CASE("gltf export: one frame has no animation and bad input is refused") {
  const gdsr::GarmentMesh m = gdsr_test::grid_garment(gdsr_test::GridSpec(2, 2, 0.2, 0.2));
  gdsr_test::TempDir dir("gltf_export_bad");
  gdsr::write_gltf_sequence(dir / "one.gltf", m, {m.V});
  const nlohmann::json g = nlohmann::json::parse(slurp(dir / "one.gltf"));
  CHECK_FALSE(g.contains("animations"));
  CHECK_FALSE(g["meshes"][0]["primitives"][0].contains("targets"));

  gdsr::Points3 nan = m.V;
  nan(1, 1) = std::nan("");
  CHECK_THROWS_WITH_AS(gdsr::write_gltf_sequence(dir / "bad.gltf", m, {m.V, nan}),
                       doctest::Contains("frame 1 has a non-finite position"), gdsr::Error);
  CHECK_THROWS_WITH_AS(gdsr::write_gltf_sequence(dir / "bad.gltf", m, {m.V, m.V.topRows(3)}),
                       doctest::Contains("frame 1 has 3 vertices"), gdsr::Error);
  CHECK_THROWS_AS(gdsr::write_gltf_sequence(dir / "bad.glb", m, {m.V}), gdsr::Error);
  CHECK_THROWS_AS(gdsr::write_gltf_sequence(dir / "bad.gltf", m, {}), gdsr::Error);
  CHECK_FALSE(std::filesystem::exists(dir / "bad.gltf"));
}

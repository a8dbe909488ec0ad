#include "gdsr/data/dataset.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

using namespace gdsr;
using gdsr_test::TempDir;
namespace fs = std::filesystem;

namespace {

// A small synthetic dataset: a seamed tube (LR) and its subdivision (HR), T frames of a
// swaying motion, and a "body" (a small box) moving along.
Dataset small_dataset(int T) {
  Dataset d;
  d.lr = gdsr_test::grid_garment(gdsr_test::GridSpec(6, 3, 0.6, 0.3).tube());
  d.hr = subdivide_midpoint(d.lr);
  d.corr = compute_correspondence(d.lr, d.hr);
  d.raster = rasterize_uv(d.hr.UV, d.hr.FUV, 64, 64, 2);
  TriMesh box;
  box.V.resize(4, 3);
  box.V << 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1;
  box.F.resize(4, 3);
  box.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  d.body_faces = box.F;
  for (int t = 0; t < T; ++t) {
    Points3 lr = d.lr.V;
    lr.col(0).array() += 0.01 * std::sin(0.3 * t);
    d.lr_frames.push_back(lr);
    Points3 hr = upsample(d.corr, lr);
    hr.col(2).array() += 0.001 * t;
    d.hr_frames.push_back(hr);
    d.body_frames.push_back(box.V.array() + 0.01 * t);
  }
  d.manifest.garment = "tube";
  d.manifest.source_motion = "synthetic";
  d.manifest.sim_params = {{"substeps", 4}};
  update_manifest_counts(d);
  return d;
}

std::string load_error(const std::string& dir) {
  try {
    load_dataset(dir);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

}  // namespace

TEST_CASE("dataset: binary arrays round trip and detect corruption") {
  TempDir dir("arrays");
  std::vector<Points3> frames(3, Points3::Random(5, 3));
  frames[1] *= 2;
  write_array(dir / "f.bin", frames_to_array(frames));
  const std::vector<Points3> back = array_to_frames(read_array(dir / "f.bin"), "f");
  REQUIRE(back.size() == 3);
  for (int t = 0; t < 3; ++t) CHECK((back[t] - frames[t]).cwiseAbs().maxCoeff() < 1e-6);

  // Flip one payload byte: checksum mismatch.
  {
    std::fstream f(dir / "f.bin", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(40);
    char c = 0;
    f.read(&c, 1);
    f.seekp(40);
    c ^= 0x5a;
    f.write(&c, 1);
  }
  CHECK_THROWS_WITH_AS(read_array(dir / "f.bin"), doctest::Contains("checksum"), std::runtime_error);
  CHECK_NOTHROW(read_array(dir / "f.bin", false));
  // Truncated file.
  fs::resize_file(dir / "f.bin", 30);
  CHECK_THROWS_WITH_AS(read_array(dir / "f.bin"), doctest::Contains("f.bin"), std::runtime_error);
  CHECK_THROWS_WITH_AS(read_array(dir / "none.bin"), doctest::Contains("missing file"), std::runtime_error);
  std::vector<Points3> ragged{Points3::Zero(2, 3), Points3::Zero(3, 3)};
  CHECK_THROWS_AS(frames_to_array(ragged), std::runtime_error);
}

TEST_CASE("dataset: write and load round trip") {
  TempDir dir("roundtrip");
  const Dataset d = small_dataset(5);
  const std::string out = dir / "tube";
  write_dataset(out, d);
  CHECK_FALSE(fs::exists(dir / "tube.tmp"));
  write_dataset(out, d);  // overwrite an existing dataset
  CHECK_FALSE(fs::exists(dir / "tube.old"));
  const Dataset r = load_dataset(out);
  CHECK(r.manifest.garment == "tube");
  CHECK(r.manifest.frames == 5);
  CHECK(r.manifest.sim_params["substeps"] == 4);
  CHECK(r.lr.F == d.lr.F);
  CHECK(r.hr.FUV == d.hr.FUV);
  CHECK(r.hr.uv_to_vertex == d.hr.uv_to_vertex);
  REQUIRE(r.hr_frames.size() == 5);
  REQUIRE(r.body_frames.size() == 5);
  CHECK(r.body_faces == d.body_faces);
  for (int t = 0; t < 5; ++t) {
    CHECK((r.hr_frames[t] - d.hr_frames[t]).cwiseAbs().maxCoeff() < 1e-6);
    CHECK((r.lr_frames[t] - d.lr_frames[t]).cwiseAbs().maxCoeff() < 1e-6);
  }
  CHECK(r.corr.hr_from_lr.tri == d.corr.hr_from_lr.tri);
  CHECK((r.corr.lr_from_hr.bary - d.corr.lr_from_hr.bary).cwiseAbs().maxCoeff() == 0.0);
  CHECK(r.corr.hr_nearest_lr == d.corr.hr_nearest_lr);
  CHECK(r.raster.tri == d.raster.tri);
  CHECK(r.raster.scale == d.raster.scale);
  // The loaded correspondences still map the loaded LR frames onto the HR frames.
  CHECK((upsample(r.corr, r.lr_frames[0]) - d.hr_frames[0]).cwiseAbs().maxCoeff() < 1e-6);
  const Dataset m = load_dataset(out, LoadOptions{false, true});
  CHECK(m.lr_frames.empty());
}

TEST_CASE("dataset: loader errors are specific") {
  TempDir dir("errors");
  const Dataset d = small_dataset(4);
  auto fresh = [&](const std::string& name) {
    const std::string p = dir / name;
    write_dataset(p, d);
    return p;
  };
  CHECK(load_error(dir / "nothing").find("no dataset folder") != std::string::npos);

  std::string p = fresh("missing_frames");
  fs::remove(p + "/hr_frames.bin");
  CHECK(load_error(p).find("missing file") != std::string::npos);
  CHECK(load_error(p).find("hr_frames.bin") != std::string::npos);

  p = fresh("frame_count");
  write_array(p + "/lr_frames.bin", frames_to_array({d.lr_frames.begin(), d.lr_frames.end() - 1}));
  CHECK(load_error(p).find("mismatched frame counts") != std::string::npos);

  p = fresh("vertex_count");
  std::vector<Points3> fewer;
  for (const auto& f : d.hr_frames) fewer.push_back(f.topRows(f.rows() - 1));
  write_array(p + "/hr_frames.bin", frames_to_array(fewer));
  CHECK(load_error(p).find("vertex count mismatch") != std::string::npos);
  CHECK(load_error(p).find("HR frames") != std::string::npos);

  p = fresh("nan");
  std::vector<Points3> bad = d.body_frames;
  bad[2](1, 1) = std::numeric_limits<double>::quiet_NaN();
  write_array(p + "/body_frames.bin", frames_to_array(bad));
  CHECK(load_error(p).find("NaN") != std::string::npos);
  CHECK(load_error(p).find("frame 2 vertex 1") != std::string::npos);

  p = fresh("manifest_count");
  {
    nlohmann::json j;
    std::ifstream(p + "/manifest.json") >> j;
    j["lr"]["vertices"] = 3;
    write_text(p + "/manifest.json", j.dump());
  }
  CHECK(load_error(p).find("vertex count mismatch") != std::string::npos);

  p = fresh("manifest_key");
  {
    nlohmann::json j;
    std::ifstream(p + "/manifest.json") >> j;
    j.erase("fps");
    write_text(p + "/manifest.json", j.dump());
  }
  CHECK(load_error(p).find("missing key 'fps'") != std::string::npos);

  p = fresh("degenerate_uv");
  GarmentMesh flat = d.lr;
  flat.UV.row(flat.FUV(3, 2)) = 0.5 * (flat.UV.row(flat.FUV(3, 0)) + flat.UV.row(flat.FUV(3, 1)));  // collinear
  write_obj(p + "/lr.obj", flat);
  CHECK(load_error(p).find("degenerate UV triangle") != std::string::npos);

  p = fresh("bad_obj");
  write_text(p + "/hr.obj", "v 0 0 0\nv 1 0 oops\n");
  CHECK(load_error(p).find("hr.obj:2") != std::string::npos);
}

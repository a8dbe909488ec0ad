// Small garment meshes and temp folders for the data tests (header only, test code).
#pragma once

#include "gdsr/data/dataset.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "tests/support/grid_garment.hpp"
#include "gdsr/geometry/uv_raster.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

namespace gdsr_test {

// A fresh empty folder under the system temp dir, removed on destruction.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& name) {
    path = std::filesystem::temp_directory_path() / ("gdsr_test_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

// The whole file at path ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A copy of BVH file `bvh` in dir with its thighs renamed ("LeftUpLeg" -> "LeftFemr"), so that
// no joint name says thigh or hip: the skeleton body cannot find its hips. Returns the path
// ("" when `bvh` cannot be read).
inline std::string bvh_without_thighs(const TempDir& dir, const std::string& bvh) {
  if (!std::ifstream(bvh)) return "";
  std::string text = slurp(bvh);
  for (size_t at = text.find("UpLeg"); at != std::string::npos; at = text.find("UpLeg", at))
    text.replace(at, 5, "Femr");
  const std::string out = dir / "renamed.bvh";
  std::ofstream(out) << text;
  return out;
}

// The UV layout of g as a flat mesh (z = 0), as Marvelous Designer exports the pattern.
inline gdsr::TriMesh flat_uv_mesh(const gdsr::GarmentMesh& g) {
  gdsr::TriMesh m{gdsr::Points3::Zero(g.UV.rows(), 3), g.FUV};
  m.V.leftCols(2) = g.UV;
  return m;
}

// A 4x4-quad LR sheet and an 8x8-quad HR sheet of the same UV outline (0.3 m square),
// waving over `frames` frames, the HR one with finer ripples; no body.
inline gdsr::Dataset wave_dataset(int frames = 8) {
  gdsr::Dataset d;
  d.lr = gdsr_test::grid_garment(gdsr_test::GridSpec(4, 4, 0.3, 0.3));
  d.hr = gdsr_test::grid_garment(gdsr_test::GridSpec(8, 8, 0.3, 0.3));
  for (int t = 0; t < frames; ++t) {
    const double ph = 0.4 * t;
    gdsr::Points3 lr = d.lr.V, hr = d.hr.V;
    for (int i = 0; i < lr.rows(); ++i) lr(i, 2) = 0.03 * std::sin(10 * lr(i, 0) + ph);
    for (int i = 0; i < hr.rows(); ++i)
      hr(i, 2) = 0.03 * std::sin(10 * hr(i, 0) + ph) + 0.004 * std::sin(60 * hr(i, 1) + 2 * ph);
    d.lr_frames.push_back(lr);
    d.hr_frames.push_back(hr);
  }
  d.corr = gdsr::compute_correspondence(d.lr, d.hr);
  d.raster = gdsr::rasterize_uv(d.hr.UV, d.hr.FUV, 96, 96, 2);
  d.manifest.garment = "wave";
  gdsr::update_manifest_counts(d);
  return d;
}

}  // namespace gdsr_test

// Small garment meshes, datasets with a box body, and temp folders for the data tests (header
// only, test code).
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
#include <vector>

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

// A closed, outward-oriented box [x0,x1] x [y0,y1] x [z0,z1]: 8 vertices, 12 triangles.
inline gdsr::TriMesh box(double x0, double x1, double y0, double y1, double z0, double z1) {
  gdsr::TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.V.row(i) << (i & 1 ? x1 : x0), (i & 2 ? y1 : y0), (i & 4 ? z1 : z0);
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3,  // z0 (normal -z)
      4, 5, 6, 5, 7, 6,     // z1 (+z)
      0, 1, 4, 1, 5, 4,     // y0 (-y)
      2, 6, 3, 3, 6, 7,     // y1 (+y)
      0, 4, 2, 2, 4, 6,     // x0 (-x)
      1, 3, 5, 3, 7, 5;     // x1 (+x)
  return m;
}

// LR 4x4 and HR 8x8 quads over 0.3 m x 0.3 m, every frame stretched by 1.1 along x, HR 2 mm
// above LR; a box body whose top rises to z = top[t].
inline gdsr::Dataset stretched_dataset(const std::vector<double>& top) {
  gdsr::Dataset d;
  d.lr = gdsr_test::grid_garment(gdsr_test::GridSpec(4, 4, 0.3, 0.3));
  d.hr = gdsr_test::grid_garment(gdsr_test::GridSpec(8, 8, 0.3, 0.3));
  for (double z : top) {
    gdsr::Points3 lr = d.lr.V, hr = d.hr.V;
    lr.col(0) *= 1.1;
    hr.col(0) *= 1.1;
    hr.col(2).array() += 0.002;
    d.lr_frames.push_back(lr);
    d.hr_frames.push_back(hr);
    const gdsr::TriMesh b = box(0.1, 0.2, 0.1, 0.2, -0.05, z);
    d.body_frames.push_back(b.V);
    d.body_faces = b.F;
  }
  d.corr = gdsr::compute_correspondence(d.lr, d.hr);
  d.raster = gdsr::rasterize_uv(d.hr.UV, d.hr.FUV, 64, 64, 2);
  d.manifest.garment = "stretched";
  gdsr::update_manifest_counts(d);
  return d;
}

// Adds a second body box to d's box body: `far` in every frame but `frame`, `near` there.
inline void add_second_part(gdsr::Dataset& d, const gdsr::TriMesh& far, const gdsr::TriMesh& near, size_t frame = 2) {
  gdsr::Faces F(d.body_faces.rows() * 2, 3);
  F << d.body_faces, (far.F.array() + 8).matrix();
  d.body_faces = F;
  for (size_t t = 0; t < d.body_frames.size(); ++t) {
    gdsr::Points3 V(16, 3);
    V << d.body_frames[t], (t == frame ? near : far).V;
    d.body_frames[t] = V;
  }
  gdsr::update_manifest_counts(d);
}

}  // namespace gdsr_test

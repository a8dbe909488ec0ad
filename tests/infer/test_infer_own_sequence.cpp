// gdsr infer --lr-dir on a user's own OBJ sequence, written here by a plain OBJ writer of the
// test's own (not the project's dataset or OBJ code): an HR sequence of the right size comes
// out, and bad input gives a one-line error naming the file.
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_checkpoint.hpp"
#include "gdsr/model/model_config.hpp"
#include "infer/prediction_io.hpp"
#include "nn/checkpoint.hpp"
#include "tests/support/cli_run.hpp"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using gdsr_test::check_one_line_error;
using gdsr_test::gdsr_run;
using gdsr_test::Run;
using gdsr_test::TempDir;
namespace fs = std::filesystem;

namespace {

struct Obj {
  std::vector<std::array<double, 3>> v;
  std::vector<std::array<double, 2>> vt;
  std::vector<std::array<int, 3>> f, ft;  // 0-based; ft empty: faces without vt
};

void write_plain_obj(const std::string& path, const Obj& o) {
  std::ofstream out(path);
  for (const auto& p : o.v) out << "v " << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  for (const auto& p : o.vt) out << "vt " << p[0] << ' ' << p[1] << '\n';
  for (size_t i = 0; i < o.f.size(); ++i) {
    out << 'f';
    for (int k = 0; k < 3; ++k) {
      out << ' ' << o.f[i][k] + 1;
      if (!o.ft.empty()) out << '/' << o.ft[i][k] + 1;
    }
    out << '\n';
  }
}

// A tube of kAround x kRows vertices (millimetres), seam welded in 3-D; its flattened
// pattern has one more column (the seam's second copy). Faces correspond one to one.
constexpr int kAround = 8, kRows = 4;
constexpr double kPi = 3.14159265358979323846, kRadius = 150, kHeight = 300;

Obj tube_frame(int t) {
  Obj o;
  for (int j = 0; j < kRows; ++j)
    for (int i = 0; i < kAround; ++i) {
      const double a = 2 * kPi * i / kAround, r = kRadius * (1 + 0.05 * std::sin(0.5 * t + j));
      o.v.push_back({r * std::cos(a), kHeight * j / (kRows - 1), r * std::sin(a)});
    }
  for (int j = 0; j + 1 < kRows; ++j)
    for (int i = 0; i < kAround; ++i) {
      const int a = j * kAround + i, b = j * kAround + (i + 1) % kAround, c = a + kAround, d = b + kAround;
      o.f.push_back({a, b, d});
      o.f.push_back({a, d, c});
    }
  return o;
}

std::vector<std::array<double, 2>> pattern_uv() {
  std::vector<std::array<double, 2>> uv;
  for (int j = 0; j < kRows; ++j)
    for (int i = 0; i <= kAround; ++i) uv.push_back({2 * kPi * kRadius * i / kAround, kHeight * j / (kRows - 1)});
  return uv;
}

std::vector<std::array<int, 3>> pattern_faces() {
  std::vector<std::array<int, 3>> f;
  for (int j = 0; j + 1 < kRows; ++j)
    for (int i = 0; i < kAround; ++i) {
      const int a = j * (kAround + 1) + i, b = a + 1, c = a + kAround + 1, d = b + kAround + 1;
      f.push_back({a, b, d});
      f.push_back({a, d, c});
    }
  return f;
}

// The flattened pattern as Marvelous Designer writes it: the layout in v (z = 0).
Obj flat_pattern() {
  Obj o;
  for (const auto& p : pattern_uv()) o.v.push_back({p[0], p[1], 0.0});
  o.f = pattern_faces();
  return o;
}

// A small tetrahedron far from the tube.
Obj body_frame(int t) {
  Obj o;
  o.v = {{{1000.0 + t, 0, 0}}, {{1100.0 + t, 0, 0}}, {{1000.0 + t, 100, 0}}, {{1000.0 + t, 0, 100}}};
  o.f = {{{0, 2, 1}}, {{0, 1, 3}}, {{0, 3, 2}}, {{1, 2, 3}}};
  return o;
}

constexpr int kFrames = 11;  // frame_0 .. frame_10: frame_10 must sort after frame_9

void write_sequence(const TempDir& dir) {
  fs::create_directories(dir / "lr");
  fs::create_directories(dir / "body");
  for (int t = 0; t < kFrames; ++t) {
    write_plain_obj(dir / ("lr/frame_" + std::to_string(t) + ".obj"), tube_frame(t));
    write_plain_obj(dir / ("body/body_" + std::to_string(t) + ".obj"), body_frame(t));
  }
  write_plain_obj(dir / "lr_flat.obj", flat_pattern());
  Obj hr = tube_frame(0);  // an "HR" garment at the LR resolution, with its pattern in vt
  hr.vt = pattern_uv();
  hr.ft = pattern_faces();
  write_plain_obj(dir / "hr_garment.obj", hr);
}

void write_tiny_checkpoint(const std::string& path) {
  const gdsr::ModelConfig cfg = gdsr::load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
  const gdsr::GDSR<float> model(cfg);
  nn::save_checkpoint<float>(path, model, nullptr, 0, gdsr::checkpoint_metadata(cfg));
}

// Reads OUT's prediction and checks frames x vertices, all finite.
void check_prediction(const std::string& out, int frames, int hr_vertices, int lr_vertices) {
  const gdsr::Prediction p = gdsr::read_prediction(out);
  REQUIRE(static_cast<int>(p.G.size()) == frames);
  REQUIRE(static_cast<int>(p.C_hat.size()) == frames);
  for (const auto& G : p.G) {
    CHECK(G.rows() == hr_vertices);
    CHECK(G.allFinite());
  }
  CHECK(p.C_hat[0].rows() == lr_vertices);
  // The prediction follows the input: HR vertices stay near the tube (radius 150 mm).
  const double r = std::sqrt(p.G.back()(0, 0) * p.G.back()(0, 0) + p.G.back()(0, 2) * p.G.back()(0, 2));
  CHECK(r < 1.0);
}

}  // namespace

TEST_CASE("infer cli: own OBJ sequence in HR subdivided or from an HR OBJ") {
  TempDir dir("cli_infer_own");
  write_sequence(dir);
  const std::string ckpt = dir / "tiny.ckpt";
  write_tiny_checkpoint(ckpt);
  const std::string base = "infer --model '" + ckpt + "' --lr-dir '" + (dir / "lr") + "' --lr-uv '" +
                           (dir / "lr_flat.obj") + "' --scale 0.001 --fps 30";
  const int lr_v = kAround * kRows;
  // 1-to-4 subdivision with the seam welded: V + E vertices (an open seam would add kRows * 3 - ...).
  const int edges = kAround * kRows + 2 * kAround * (kRows - 1);
  const int faces = 2 * kAround * (kRows - 1);

  const Run sub = gdsr_run(dir, base + " --body-dir '" + (dir / "body") + "' --out '" + (dir / "sub") + "'");
  REQUIRE_MESSAGE(sub.status == 0, sub.err);
  CHECK(sub.out.find("read 11 frames") != std::string::npos);
  check_prediction(dir / "sub", kFrames, lr_v + edges, lr_v);
  CHECK(fs::exists(dir / "sub/preview.png"));
  // gdsr export on the prediction, with the same input flags in place of --data.
  const std::string exp = " --lr-dir '" + (dir / "lr") + "' --lr-uv '" + (dir / "lr_flat.obj") + "' --scale 0.001";
  const Run ex = gdsr_run(dir, "export --pred '" + (dir / "sub") + "'" + exp + " --out '" + (dir / "exp") + "'");
  REQUIRE_MESSAGE(ex.status == 0, ex.err);
  CHECK(fs::exists(dir / "exp/gdsr.gltf"));
  CHECK(fs::exists(dir / "exp/lr.gltf"));
  CHECK_FALSE(fs::exists(dir / "exp/hr.gltf"));  // no HR simulation of the user's sequence
  check_one_line_error(gdsr_run(dir, "export --pred '" + (dir / "sub") + "'" + exp + " --subdivide 2 --out '" +
                                         (dir / "exp2") + "'"),
                       "vertices");
  CHECK_FALSE(fs::exists(dir / "exp2"));

  const Run sub2 = gdsr_run(dir, base + " --subdivide 2 --frames 2 --obj-every 1 --out '" + (dir / "sub2") + "'");
  REQUIRE_MESSAGE(sub2.status == 0, sub2.err);
  check_prediction(dir / "sub2", 2, lr_v + edges + (2 * edges + 3 * faces), lr_v);
  CHECK(fs::exists(dir / "sub2/hr_00001.obj"));

  const Run hr = gdsr_run(dir, base + " --hr-uv '" + (dir / "hr_garment.obj") + "' --out '" + (dir / "hr") + "'");
  REQUIRE_MESSAGE(hr.status == 0, hr.err);
  check_prediction(dir / "hr", kFrames, lr_v, lr_v);
}

TEST_CASE("infer cli: bad own sequences give a one-line error naming the file") {
  TempDir dir("cli_infer_own_bad");
  const std::string ckpt = dir / "tiny.ckpt";
  write_tiny_checkpoint(ckpt);
  const std::string out = dir / "out";
  const std::string base = "infer --model '" + ckpt + "' --lr-dir '" + (dir / "lr") + "' --lr-uv '" +
                           (dir / "lr_flat.obj") + "' --scale 0.001 --out '" + out + "'";

  write_sequence(dir);  // a gap: frame 5 missing
  fs::remove(dir / "lr/frame_5.obj");
  check_one_line_error(gdsr_run(dir, base), "frame_6.obj: frame 6 follows frame 4");

  write_sequence(dir);  // one frame with an extra vertex
  {
    Obj o = tube_frame(3);
    o.v.push_back({0, 0, 0});
    write_plain_obj(dir / "lr/frame_3.obj", o);
  }
  check_one_line_error(gdsr_run(dir, base), "frame_3.obj: 33 vertices");

  write_sequence(dir);  // a NaN coordinate
  std::ofstream(dir / "lr/frame_4.obj", std::ios::app) << "v 0 nan 0\n";
  check_one_line_error(gdsr_run(dir, base), "frame_4.obj");
  check_one_line_error(gdsr_run(dir, base), "non-finite");

  write_sequence(dir);  // a body folder one frame short
  fs::remove(dir / "body/body_10.obj");
  check_one_line_error(gdsr_run(dir, base + " --body-dir '" + (dir / "body") + "'"),
                       "body: 10 body OBJ files, but 11 LR frames");

  write_sequence(dir);  // a pattern with one face fewer than the 3-D mesh
  {
    Obj flat = flat_pattern();
    flat.f.pop_back();
    write_plain_obj(dir / "lr_flat.obj", flat);
  }
  check_one_line_error(gdsr_run(dir, base), "lr_flat.obj: the flattened OBJ has 47 triangles");

  write_sequence(dir);
  check_one_line_error(gdsr_run(dir, base + " --subdivide 3"), "--subdivide must be 1 or 2");
  check_one_line_error(gdsr_run(dir, "infer --model '" + ckpt + "' --lr-dir '" + (dir / "lr") + "'"), "--lr-uv");
  check_one_line_error(gdsr_run(dir, "infer --model '" + ckpt + "'"), "exactly one of --data and --lr-dir");
  check_one_line_error(gdsr_run(dir, base + " --body-dir '" + (dir / "nobody") + "'"), "nobody: no such folder");
  CHECK_FALSE(fs::exists(out));
}

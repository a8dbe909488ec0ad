// Marvelous Designer import (gdsr/data/md_import.hpp) from per-frame OBJ exports written here.
#include "gdsr/data/md_import.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

using namespace gdsr;
using gdsr_test::TempDir;
namespace fs = std::filesystem;

namespace {
void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }
}  // namespace

TEST_CASE("md import: Marvelous Designer import from per-frame OBJs") {
  TempDir dir("md");
  // Exports in millimetres, as MD writes them. 3-D frames are welded; flattened OBJs hold
  // the pattern in x/y with z = 0 and the same faces in the same order.
  const GarmentMesh lr = gdsr_test::grid_garment(gdsr_test::GridSpec(6, 3, 0.6, 0.3).tube());
  const GarmentMesh hr = subdivide_midpoint(lr);
  const int T = 4;
  for (const char* sub : {"lr", "hr", "body"}) fs::create_directories(dir / sub);
  auto flat_obj = [](const GarmentMesh& g) {
    TriMesh m;
    m.V = Points3::Zero(g.UV.rows(), 3);
    m.V.leftCols(2) = g.UV * 1000.0;
    m.F = g.FUV;
    return m;
  };
  write_obj(dir / "lr_flat.obj", flat_obj(lr));
  write_obj(dir / "hr_flat.obj", flat_obj(hr));
  for (int t = 0; t < T; ++t) {
    // Names with unpadded numbers: frame 10 must sort after frame 9.
    const std::string n = std::to_string(t * 5);
    write_obj(dir / ("lr/skirt_" + n + ".obj"), TriMesh{(lr.V.array() + 0.01 * t).matrix() * 1000.0, lr.F});
    write_obj(dir / ("hr/skirt_" + n + ".obj"), TriMesh{(hr.V.array() + 0.01 * t).matrix() * 1000.0, hr.F});
    write_obj(dir / ("body/body_" + n + ".obj"),
              TriMesh{Points3::Constant(4, 3, 10.0 * t) + Points3::Identity(4, 3) * 100.0,
                      (Faces(4, 3) << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3).finished()});
  }
  MdImportOptions opt;
  opt.lr_dir = dir / "lr";
  opt.hr_dir = dir / "hr";
  opt.lr_uv = dir / "lr_flat.obj";
  opt.hr_uv = dir / "hr_flat.obj";
  opt.body_dir = dir / "body";
  opt.scale = 0.001;
  opt.garment = "tube";
  opt.raster_size = 128;
  int calls = 0;
  opt.progress = [&](int done, int total) {
    ++calls;
    CHECK(done <= total);
  };
  const Dataset d = import_md(opt);
  CHECK(calls == 3 * T);
  CHECK(d.manifest.frames == T);
  CHECK(d.lr.V.rows() == lr.V.rows());
  CHECK(d.lr.UV.rows() == lr.UV.rows());
  CHECK(d.hr.uv_to_vertex == hr.uv_to_vertex);
  CHECK((d.hr.UV - hr.UV).cwiseAbs().maxCoeff() < 1e-9);
  CHECK((d.hr_frames[3] - (hr.V.array() + 0.03).matrix()).cwiseAbs().maxCoeff() < 1e-8);
  CHECK(d.body_frames[2](0, 0) == doctest::Approx(0.12));
  CHECK(d.manifest.lr_particle_distance == doctest::Approx(mean_edge_length(lr.V, lr.F)));
  // Subdivided HR: the imported correspondences are exact.
  CHECK((upsample(d.corr, d.lr_frames[1]) - d.hr_frames[1]).cwiseAbs().maxCoeff() < 1e-8);
  write_dataset(dir / "out", d);
  CHECK(load_dataset(dir / "out").manifest.hr_vertices == hr.V.rows());

  SUBCASE("unwelded 3-D exports are welded on request") {
    // Unwelded: one 3-D vertex per UV vertex (seam copies coincide), faces = FUV.
    for (int t = 0; t < T; ++t) {
      Points3 X(hr.UV.rows(), 3);
      for (int u = 0; u < hr.UV.rows(); ++u) X.row(u) = (hr.V.row(hr.uv_to_vertex[u]).array() + 0.01 * t) * 1000.0;
      write_obj(dir / ("hr/skirt_" + std::to_string(t * 5) + ".obj"), TriMesh{X, hr.FUV});
    }
    CHECK(import_md(opt).hr.V.rows() == hr.UV.rows());  // not welded: the seam stays open
    opt.weld = 1e-4;
    const Dataset w = import_md(opt);
    CHECK(w.hr.V.rows() == hr.V.rows());
    CHECK(unique_edges(w.hr.F).rows() == unique_edges(hr.F).rows());
    CHECK((upsample(w.corr, w.lr_frames[2]) - w.hr_frames[2]).cwiseAbs().maxCoeff() < 1e-8);
    opt.weld = 0.2;  // absurd: collapses triangles
    CHECK_THROWS_WITH_AS(import_md(opt), doctest::Contains("collapses"), std::runtime_error);
  }
  SUBCASE("mismatched frame counts") {
    fs::remove(dir / "hr/skirt_15.obj");
    CHECK_THROWS_WITH_AS(import_md(opt), doctest::Contains("mismatched frame counts"), std::runtime_error);
  }
  SUBCASE("frame with a different vertex count") {
    write_obj(dir / "lr/skirt_10.obj", TriMesh{lr.V.topRows(lr.V.rows() - 1), lr.F.topRows(3)});
    CHECK_THROWS_WITH_AS(import_md(opt), doctest::Contains("skirt_10.obj"), std::runtime_error);
  }
  SUBCASE("flattened mesh with other faces") {
    TriMesh f = flat_obj(lr);
    f.F = f.F.topRows(f.F.rows() - 1).eval();
    write_obj(dir / "lr_flat.obj", f);
    CHECK_THROWS_WITH_AS(import_md(opt), doctest::Contains("one to one"), std::runtime_error);
  }
  SUBCASE("NaN coordinate") {
    write_text(dir / "hr/skirt_5.obj", "v nan 0 0\n");
    CHECK_THROWS_WITH_AS(import_md(opt), doctest::Contains("skirt_5.obj:1"), std::runtime_error);
  }
}

TEST_CASE("md import: frame sequences step evenly and a gap names the file") {
  TempDir dir("md_seq");
  auto touch = [&](const std::string& name) { write_text(dir / name, "v 0 0 0\n"); };
  for (const char* n : {"a_0.obj", "a_5.obj", "a_10.obj", "a_15.obj"}) touch(n);
  const std::vector<std::string> ok = list_frame_sequence(dir.path.string());
  REQUIRE(ok.size() == 4);
  CHECK(fs::path(ok[2]).filename() == "a_10.obj");  // natural order
  fs::remove(dir / "a_10.obj");
  CHECK_THROWS_WITH_AS(list_frame_sequence(dir.path.string()),
                       doctest::Contains("a_15.obj: frame 15 follows frame 5 (step 5 before): missing frames"),
                       std::runtime_error);
  touch("a_10.obj");
  touch("a_05.obj");
  CHECK_THROWS_WITH_AS(list_frame_sequence(dir.path.string()), doctest::Contains("appears twice"),
                       std::runtime_error);
}

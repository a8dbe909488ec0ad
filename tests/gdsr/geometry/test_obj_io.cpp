#include "gdsr/geometry/obj_io.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <fstream>

using namespace gdsr;
using gdsr_test::TempDir;

namespace {
void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string error_of(const std::string& path) {
  try {
    read_obj(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("obj_io: corner formats, polygons and negative indices") {
  TempDir dir("obj_formats");
  write_text(dir / "a.obj",
             "# comment\n"
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\n"
             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 1.5\n"
             "vn 0 0 1\n"
             "o thing\ng group\nusemtl m\ns off\n"
             "f 1/1 2/2 3/3 4/4\n"                            // quad -> 2 triangles
             "f 1//1 2//1 3//1\n"                             // v//vn: no UV on this face
             "f -5/-5/1 -4/-4/1 -3/-3/1 -1/-1/1 -2/-2/1\n");  // pentagon, relative indices
  const ObjData d = read_obj(dir / "a.obj");
  CHECK(d.V.rows() == 5);
  CHECK(d.VT.rows() == 5);
  REQUIRE(d.F.rows() == 2 + 1 + 3);
  CHECK(d.F.row(0) == Eigen::RowVector3i(0, 1, 2));
  CHECK(d.F.row(1) == Eigen::RowVector3i(0, 2, 3));
  CHECK(d.FT(2, 0) == -1);
  CHECK(d.F.row(5) == Eigen::RowVector3i(0, 4, 3));
  CHECK(d.FT.row(5) == Eigen::RowVector3i(0, 4, 3));
  CHECK_FALSE(d.has_uv());
}

TEST_CASE("obj_io: garment round trip keeps UV seams and faces") {
  TempDir dir("obj_roundtrip");
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(6, 3, 0.6, 0.3).tube());
  write_obj(dir / "g.obj", g);
  const GarmentMesh r = read_obj_garment(dir / "g.obj");
  CHECK(r.V.rows() == g.V.rows());
  CHECK(r.UV.rows() == g.UV.rows());
  CHECK(r.V.rows() < r.UV.rows());  // the seam has two UV copies
  CHECK(r.F == g.F);
  CHECK(r.FUV == g.FUV);
  CHECK(r.uv_to_vertex == g.uv_to_vertex);
  CHECK((r.V - g.V).cwiseAbs().maxCoeff() < 1e-8);
  CHECK((r.UV - g.UV).cwiseAbs().maxCoeff() < 1e-8);

  TriMesh t{g.V, g.F};
  write_obj(dir / "t.obj", t);
  const TriMesh rt = read_obj_mesh(dir / "t.obj");
  CHECK(rt.F == t.F);
  CHECK((rt.V - t.V).cwiseAbs().maxCoeff() < 1e-8);
  CHECK_THROWS_WITH_AS(read_obj_garment(dir / "t.obj"), doctest::Contains("vt"), std::runtime_error);
}

TEST_CASE("obj_io: errors name the file and the line") {
  TempDir dir("obj_errors");
  write_text(dir / "bad_number.obj", "v 0 0 0\nv 1 0 x\nf 1 2 1\n");
  CHECK(error_of(dir / "bad_number.obj").find("bad_number.obj:2") != std::string::npos);
  CHECK(error_of(dir / "bad_number.obj").find("malformed number") != std::string::npos);

  write_text(dir / "short.obj", "v 0 0\n");
  CHECK(error_of(dir / "short.obj").find("short.obj:1") != std::string::npos);

  write_text(dir / "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  CHECK(error_of(dir / "range.obj").find("range.obj:4") != std::string::npos);
  CHECK(error_of(dir / "range.obj").find("out of range") != std::string::npos);

  write_text(dir / "empty.obj", "# nothing\n");
  CHECK(error_of(dir / "empty.obj").find("empty mesh") != std::string::npos);

  write_text(dir / "nofaces.obj", "v 0 0 0\n");
  CHECK(error_of(dir / "nofaces.obj").find("empty mesh") != std::string::npos);

  write_text(dir / "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  CHECK(error_of(dir / "nan.obj").find("nan.obj:2") != std::string::npos);
  CHECK(error_of(dir / "nan.obj").find("non-finite") != std::string::npos);

  write_text(dir / "corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2/ 3\n");
  CHECK(error_of(dir / "corner.obj").find("corner.obj:4") != std::string::npos);

  write_text(dir / "twoface.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n");
  CHECK(error_of(dir / "twoface.obj").find("fewer than 3") != std::string::npos);

  CHECK(error_of(dir / "missing.obj").find("cannot open") != std::string::npos);

  // One vt used with two different v: not a garment.
  write_text(dir / "vtclash.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
             "f 1/1 2/2 3/3\nf 2/1 4/2 3/3\n");
  CHECK_THROWS_WITH_AS(read_obj_garment(dir / "vtclash.obj"), doctest::Contains("two different vertices"),
                       std::runtime_error);
}

TEST_CASE("obj_io: write_file_atomic replaces the file and leaves no temp") {
  TempDir dir("obj_atomic");
  write_file_atomic(dir / "x.txt", "one");
  write_file_atomic(dir / "x.txt", "two");
  std::ifstream in(dir / "x.txt");
  std::string s;
  in >> s;
  CHECK(s == "two");
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path)) files += e.is_regular_file();
  CHECK(files == 1);
  CHECK_THROWS_AS(write_file_atomic(dir / "no/such/dir/x.txt", "a"), std::runtime_error);
}

// export_sequence: the formats asked for, named as documented, and bad frames refused
// before anything is written.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "gdsr/io/sequence_export.hpp"
#include "tests/support/data_fixtures.hpp"
#include "tests/support/grid_garment.hpp"

#include <cmath>

TEST_CASE("sequence export: files per format and refusal of NaN frames") {
  const gdsr::GarmentMesh m = gdsr_test::grid_garment(gdsr_test::GridSpec(3, 2, 0.3, 0.2));
  std::vector<gdsr::Points3> frames{m.V, m.V * 1.1, m.V * 1.2};
  gdsr_test::TempDir dir("sequence_export");
  gdsr::SequenceExportOptions opt;
  opt.first_frame = 10;
  opt.gltf = false;
  const nlohmann::json j = gdsr::export_sequence(dir / "a", "cloth", m, frames, opt);
  CHECK_FALSE(j.contains("gltf"));
  CHECK(j["pc2"] == "cloth.pc2");
  CHECK(j["rest_obj"] == "cloth_rest.obj");
  CHECK(j["obj"] == nlohmann::json{"obj/cloth_00010.obj", "obj/cloth_00011.obj", "obj/cloth_00012.obj"});
  CHECK(j["frames"] == 3);
  CHECK_FALSE(std::filesystem::exists(dir / "a/cloth.gltf"));
  CHECK(std::filesystem::exists(dir / "a/obj/cloth_00012.obj"));

  frames[1](2, 0) = std::nan("");
  CHECK_THROWS_WITH_AS(gdsr::export_sequence(dir / "b", "cloth", m, frames),
                       doctest::Contains("frame 1 has a non-finite"), gdsr::Error);
  CHECK_FALSE(std::filesystem::exists(dir / "b"));
}

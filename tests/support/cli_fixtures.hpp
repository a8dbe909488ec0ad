// Fixtures of the CLI tests that need MD-style exports, a dataset replace or a prediction
// folder: written with the library, then handed to the built gdsr binary (header only).
#pragma once

#include "gdsr/data/dataset.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "tests/support/data_fixtures.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace gdsr_test {

// Names in `dir` that start with `prefix` (leftover temp / old folders).
inline int count_prefixed(const std::string& dir, const std::string& prefix) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    n += e.path().filename().string().rfind(prefix, 0) == 0;
  return n;
}

// MD-style exports of the waving sheet: dir/lr, dir/hr frame folders and flattened OBJs.
inline void write_exports(const TempDir& dir, int frames) {
  const gdsr::Dataset d = wave_dataset(frames);
  std::filesystem::create_directories(dir / "lr");
  std::filesystem::create_directories(dir / "hr");
  gdsr::write_obj(dir / "lr_flat.obj", flat_uv_mesh(d.lr));
  gdsr::write_obj(dir / "hr_flat.obj", flat_uv_mesh(d.hr));
  for (int t = 0; t < frames; ++t) {
    gdsr::write_obj(dir / ("lr/f" + std::to_string(t) + ".obj"), gdsr::TriMesh{d.lr_frames[t], d.lr.F});
    gdsr::write_obj(dir / ("hr/f" + std::to_string(t) + ".obj"), gdsr::TriMesh{d.hr_frames[t], d.hr.F});
  }
}

inline std::string import_to(const TempDir& dir, const std::string& out) {
  return "data import-md --lr-dir '" + (dir / "lr") + "' --hr-dir '" + (dir / "hr") + "' --lr-uv '" +
         (dir / "lr_flat.obj") + "' --hr-uv '" + (dir / "hr_flat.obj") + "' --out '" + out + "'";
}

inline std::string make_to(const std::string& out) {
  return "data make --garment skirt_short --seconds 0.1 --lr-pd 0.08 --hr-pd 0.06 --rest-blend 2 --raster 64 --out '" +
         out + "'";
}

// A prediction folder of frames [first, first + G.size()) recorded as made on `dataset`.
inline void write_pred(const std::string& dir, const std::vector<gdsr::Points3>& G, int first,
                       const std::string& dataset, long long frames) {
  std::filesystem::create_directories(dir);
  gdsr::Array a;
  a.dtype = gdsr::DType::f32;
  const uint64_t n = G.empty() ? 81 : static_cast<uint64_t>(G[0].rows());
  a.dims = {static_cast<uint64_t>(G.size()), n, 3};
  for (const auto& g : G)
    for (int i = 0; i < g.rows(); ++i)
      for (int c = 0; c < 3; ++c) {
        const float v = static_cast<float>(g(i, c));
        a.bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
      }
  gdsr::write_array(dir + "/pred_hr.bin", a);
  gdsr::write_file_atomic(dir + "/prediction.json",
                          nlohmann::json{{"first_frame", first}, {"frames", frames}, {"dataset", dataset}}.dump());
}

}  // namespace gdsr_test

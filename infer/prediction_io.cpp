#include "infer/prediction_io.hpp"

#include "gdsr/data/dataset.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/model/json_value.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace gdsr {

void write_prediction(const std::string& dir, const Prediction& p) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  remove_stale_temps(dir, {"pred_hr.bin", "pred_lr.bin", "prediction.json"});  // from killed writes
  // prediction.json is the commit: it goes first and comes back last, so a kill in between
  // leaves no prediction.json beside new arrays (read_prediction refuses such a folder).
  fs::remove((fs::path(dir) / "prediction.json"));
  write_array((fs::path(dir) / "pred_hr.bin").string(), frames_to_array(p.G));
  if (!p.C_hat.empty()) write_array((fs::path(dir) / "pred_lr.bin").string(), frames_to_array(p.C_hat));
  const nlohmann::json j{{"first_frame", p.first_frame},
                         {"frames", p.G.size()},
                         {"dataset", p.dataset},
                         {"model", p.model},
                         {"seconds_per_frame", p.seconds_per_frame},
                         {"model_seconds_per_frame", p.model_seconds_per_frame}};
  write_file_atomic((fs::path(dir) / "prediction.json").string(), j.dump(2));
}

Prediction read_prediction(const std::string& dir, bool hr_only) {
  namespace fs = std::filesystem;
  Prediction p;
  long long frames = -1;
  const std::string meta = (fs::path(dir) / "prediction.json").string();
  std::ifstream in(meta);
  if (!in) gdsr::fail(meta, "cannot open (not a folder written by gdsr infer?)");
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    p.first_frame = json_value<int>(j.at("first_frame"));
    frames = json_value<long long>(j.at("frames"));
    p.dataset = j.value("dataset", "");
    p.model = j.value("model", "");
    p.seconds_per_frame = j.value("seconds_per_frame", 0.0);
    p.model_seconds_per_frame = j.value("model_seconds_per_frame", 0.0);
  } catch (const std::exception& e) {  // bad JSON, a missing key, a number out of range
    gdsr::fail(meta, e.what());
  }
  const std::string hr = (fs::path(dir) / "pred_hr.bin").string();
  p.G = array_to_frames(read_array(hr), hr);
  if (static_cast<long long>(p.G.size()) != frames)
    gdsr::fail(hr, std::to_string(p.G.size()) + " frames but " + meta + " records " + std::to_string(frames) +
                       " (files from different runs?)");
  for (size_t t = 0; t < p.G.size(); ++t)
    if (!p.G[t].allFinite()) gdsr::fail(hr, "frame " + std::to_string(t) + " holds NaN or inf positions");
  const std::string lr = (fs::path(dir) / "pred_lr.bin").string();
  if (!hr_only && fs::exists(lr)) {
    p.C_hat = array_to_frames(read_array(lr), lr);
    if (p.C_hat.size() != p.G.size())
      gdsr::fail(lr, std::to_string(p.C_hat.size()) + " frames but pred_hr.bin has " + std::to_string(p.G.size()));
  }
  return p;
}

}  // namespace gdsr

#include "infer/prediction_io.hpp"

#include "gdsr/data/dataset.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace gdsr {

void write_prediction(const std::string& dir, const Prediction& p) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
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
  const std::string meta = (fs::path(dir) / "prediction.json").string();
  std::ifstream in(meta);
  if (!in) gdsr::fail(meta, "cannot open (not a folder written by gdsr infer?)");
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    p.first_frame = j.at("first_frame").get<int>();
    p.dataset = j.value("dataset", "");
    p.model = j.value("model", "");
    p.seconds_per_frame = j.value("seconds_per_frame", 0.0);
    p.model_seconds_per_frame = j.value("model_seconds_per_frame", 0.0);
  } catch (const nlohmann::json::exception& e) {
    gdsr::fail(meta, e.what());
  }
  const std::string hr = (fs::path(dir) / "pred_hr.bin").string();
  p.G = array_to_frames(read_array(hr), hr);
  const std::string lr = (fs::path(dir) / "pred_lr.bin").string();
  if (!hr_only && fs::exists(lr)) p.C_hat = array_to_frames(read_array(lr), lr);
  return p;
}

}  // namespace gdsr

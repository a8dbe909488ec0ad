#include "gdsr/model/model_checkpoint.hpp"

#include "gdsr/error.hpp"

#include "nn/checkpoint.hpp"

#include <nlohmann/json.hpp>

#include <stdexcept>

namespace gdsr {

std::string checkpoint_metadata(const ModelConfig& cfg) {
  nlohmann::json j;
  j["kind"] = "gdsr-model";
  j["model_config"] = model_config_to_json_text(cfg);
  return j.dump();
}

ModelConfig config_from_checkpoint(const std::string& path) {
  return config_from_checkpoint(nn::read_checkpoint(path), path);
}

ModelConfig config_from_checkpoint(const nn::Checkpoint& ck, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ck.metadata);
  } catch (const std::exception&) {
    gdsr::fail(path, "checkpoint metadata is not JSON");
  }
  if (!j.is_object() || !j.contains("model_config") || !j["model_config"].is_string())
    gdsr::fail(path, "not a GDSR model checkpoint (no model_config)");
  return model_config_from_json_text(j["model_config"].get<std::string>(), path);
}

}  // namespace gdsr

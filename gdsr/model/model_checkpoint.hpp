// A GDSR model checkpoint (nn/checkpoint.hpp format) carries its model config as JSON text
// in the metadata, so `gdsr infer` can rebuild the model from the file alone.
#pragma once

#include "gdsr/model/model_config.hpp"
#include "nn/checkpoint.hpp"

#include <string>

namespace gdsr {

// Metadata to store with a GDSR checkpoint: {"kind": "gdsr-model", "model_config": "..."}.
std::string checkpoint_metadata(const ModelConfig& cfg);
// The model config stored in the checkpoint at `path`; throws naming the file when the
// metadata is not a GDSR model's.
ModelConfig config_from_checkpoint(const std::string& path);
// The same for a checkpoint already read; `path` names it in errors.
ModelConfig config_from_checkpoint(const nn::Checkpoint& ck, const std::string& path);

}  // namespace gdsr

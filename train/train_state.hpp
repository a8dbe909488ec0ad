// What a training run carries from step to step besides the model and AdamW (which
// nn/checkpoint.hpp stores): the position in the data, the RNG streams and the best figure
// so far. Stored as JSON under "trainer" in the checkpoint metadata, so that a resumed run
// continues exactly where the checkpoint was taken.
#pragma once

#include "nn/rng.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace gdsr {

struct TrainProgress {
  int64_t step = 0;       // optimizer steps taken
  int64_t frame_pos = 0;  // training frames consumed; epoch = frame_pos / frames_per_epoch
  int epoch = -1;         // the epoch `order` belongs to (-1: nothing shuffled yet)
  std::vector<std::pair<int, int>> order;  // that epoch's shuffled (sequence, t)
  std::string order_rng;                   // std::mt19937_64 (frame order, patches), as text
  nn::Rng::State noise{};                  // the training noise stream
  int frames_per_step = 1;
  int64_t frames_per_epoch = 0;
  // One line per training sequence, "garment LR-vertices/HR-vertices frames": a resume on other
  // data (another garment with the same frame count included) is refused.
  std::vector<std::string> data;
  bool has_best = false;
  double best = 0;           // figure of the best checkpoint so far
  double interval_sum = 0;   // training totals since the last checkpoint
  int64_t interval_count = 0;
};

nlohmann::json progress_to_json(const TrainProgress& p);
// Throws a one-line gdsr::Error naming `path` when a field is missing or out of range.
TrainProgress progress_from_json(const nlohmann::json& j, const std::string& path);

}  // namespace gdsr

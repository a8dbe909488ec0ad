// Inference by roll-out (paper 3, 4.6): each frame's corrected C^_t feeds the history of
// the next; all HR vertices are predicted (A on every LR triangle), then the explicit
// collision handling moves HR vertices out of the body and between layers.
#pragma once

#include "infer/collision.hpp"
#include "gdsr/io/progress.hpp"
#include "gdsr/data/dataset.hpp"
#include "gdsr/model/gdsr_model.hpp"

#include <functional>
#include <vector>

namespace gdsr {

struct RolloutOptions {
  int first_frame = 0;
  int frames = -1;         // < 0: to the end of the sequence
  bool collisions = true;  // section 4.6 post-process
  CollisionConfig collision;
  // Each frame's history C^_{t-1}, C^_{t-2} is the dataset's HR simulation downsampled to the
  // LR mesh (training's teacher forcing) instead of the model's own output: what the model
  // scores when its history is right, beside what it scores on its own. Needs HR frames.
  bool true_history = false;
};

struct RolloutResult {
  int first_frame = 0;
  std::vector<Points3> C_hat;  // per frame: LR vertices x 3, metres
  std::vector<Points3> G;      // per frame: HR vertices x 3, metres (after collision handling)
  std::vector<CollisionStats> collisions;
  // How far each part of the model moves the garment, averaged over the frames, metres:
  // E's correction, mean |C^ - C| over LR vertices; A's residual, mean |r| over HR vertices.
  double mean_correction = 0, mean_detail = 0;
  double seconds_per_frame = 0;        // model + collision handling, wall time
  double model_seconds_per_frame = 0;  // model forward only
};

RolloutResult rollout(const GDSR<float>& model, const Dataset& d, const RolloutOptions& opt = {},
                      const ProgressFn& progress = {});

}  // namespace gdsr

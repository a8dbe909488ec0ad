// Shared by `gdsr infer` and `gdsr eval`: their common options and the roll-out of a
// checkpoint over a dataset, printed as it goes.
#pragma once

#include "gdsr/data/dataset.hpp"
#include "gdsr/data/sequence_import.hpp"
#include "infer/prediction_io.hpp"
#include "infer/rollout.hpp"

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace gdsr_cli {

struct RolloutArgs {
  std::string model, data, out = "runs/infer", pred;
  gdsr::RolloutOptions opt;
  bool no_collisions = false;
  bool lr_planes = false;       // the paper's collision passes: HR vertices pushed out of their LR vertex's plane
  double layer_offset = -1;     // m, layer pass of the collision post-process; < 0: from the dataset (see run_rollout)
  double body_offset = -1;  // m, body pass of the collision post-process; < 0: from the dataset (see run_rollout)
  std::vector<std::string> ablate;  // parts of the model switched off: "correction", "detail"
  int obj_every = 0;
  int ssim_every = 1;
  gdsr::SequenceImportOptions seq;  // the user's own LR sequence (--lr-dir ...) instead of data
};

// Loads the checkpoint a.model, rolls it out over d with a progress bar, prints a summary.
gdsr::RolloutResult run_rollout(const RolloutArgs& a, const gdsr::Dataset& d);

// The roll-out as a prediction (named after a.data and a.model).
gdsr::Prediction to_prediction(const RolloutArgs& a, gdsr::RolloutResult r);

// --data (required unless data_required is false), --first, --frames, --no-collisions, --ablate.
void add_rollout_options(CLI::App* c, RolloutArgs& a, bool data_required = true);

// --lr-dir, --lr-uv, --hr-uv, --subdivide, --body-dir, --scale, --fps: the user's own LR
// OBJ sequence (gdsr/data/sequence_import.hpp) instead of --data.
void add_sequence_options(CLI::App* c, RolloutArgs& a);

// The input: the dataset folder a.data or the user's sequence a.seq (exactly one given).
gdsr::Dataset load_input(const RolloutArgs& a);

// --model (roll out now) or --pred (a folder written by gdsr infer): exactly one.
void add_source_options(CLI::App* c, RolloutArgs& a);

// The prediction of the chosen source: run_rollout for --model, read_prediction for --pred.
gdsr::Prediction obtain_prediction(const RolloutArgs& a, const gdsr::Dataset& d);

}  // namespace gdsr_cli

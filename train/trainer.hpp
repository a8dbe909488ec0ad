// Training GDSR on one or more datasets (paper 4.5): one frame per step, teacher forcing
// (the history C^_{t-1}, C^_{t-2} is the downsampled HR ground truth) or push-forward
// (rollout_history: the model's own roll-out over the frames before), coarse loss on the
// corrected LR garment and the patch-based fine loss on the HR vertices under a batch of UV
// patches (A is evaluated only on the LR triangles those patches need). AdamW with the
// reference settings, lr step decay, the lambda schedule, periodic atomic checkpoints.
// With frames_per_step K the gradients of K frames (each loss scaled by 1/K) are summed
// before one optimizer step.
// A non-finite loss term or gradient stops training with an exception naming the term (or
// parameter) and the step before the parameters are touched, and parameters are checked
// before every save, so the last checkpoint on disk is the last good one.
// Checkpoints hold everything a run carries (train/train_state.hpp): resuming from one
// continues bit-identically to a run that was never stopped.
#pragma once

#include "gdsr/data/dataset.hpp"
#include "train/losses.hpp"
#include "gdsr/model/model_config.hpp"
#include "train/patches.hpp"

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace gdsr {

struct TrainOptions {
  ModelConfig model;
  LossConfig loss;
  PatchConfig patches;
  int epochs = 1;          // passes over all training frames (t >= 2) of all datasets, > 0
  int64_t max_steps = -1;  // stop when the run (counted from its start, resumes included)
                           // reaches this many steps; -1: no limit, otherwise > 0
  int frames_per_step = 1; // K frames' gradients averaged per optimizer step, > 0
  // Push-forward (0: teacher forcing, the reference): the history C^_{t-1}, C^_{t-2} of a
  // training frame t is the model's own, rolled out (E only, no gradient) over the K frames
  // before t from the LR simulation as `gdsr infer` starts, so training sees the inputs a
  // roll-out feeds the model rather than the downsampled HR truth.
  int rollout_history = 0;
  // Training through a roll-out (1: off): the loss of a training frame t also covers the
  // unroll - 1 frames before it, each frame's corrected history being the previous frames'
  // outputs with their gradient (backpropagation through time), so E learns to carry its own
  // state; the history before those frames is as above. Coarse loss: the mean over the
  // unrolled frames; fine loss on frame t only.
  int unroll = 1;
  // Push-forward from the truth: the roll-out of rollout_history frames starts from the
  // downsampled HR truth before it (false: from the LR input, d = 0, as a roll-out's first frame).
  bool rollout_from_truth = false;
  // Fine-loss target (false: the HR frame, the reference): the HR frame's own detail carried
  // onto the model's coarse shape (train/detail_target.hpp), so that A is not asked to learn
  // the LR-HR drape difference. Validation's vertex error is always against the HR frame.
  bool detail_target = false;
  double lr = 1e-4;        // AdamW, reference settings
  double weight_decay = 0.01;
  bool amsgrad = true;
  int64_t lr_halve_every = 50000;  // steps
  double lr_floor = 1e-6;
  bool fine = true;        // patches + hyper-net A (false: coarse correction only)
  bool vgg = true;         // VGG feature term of the fine loss
  std::string vgg_dir;     // empty: nn::vgg19_default_dir()
  uint64_t seed = 1;       // frame order, patches, noise
  std::string checkpoint;  // the last good state: every checkpoint_every steps and at the end ("" = never)
  int64_t checkpoint_every = 100;
  // The best state so far ("" = never): written at a checkpoint whose figure is the lowest
  // yet: the validation total when validation data is given, else the mean training total
  // since the previous checkpoint.
  std::string best_checkpoint;
  std::vector<const Dataset*> validation;  // scored (no gradient) at every checkpoint
  std::string resume;  // continue from this checkpoint (model, AdamW, data order, RNGs)
  // Start from this model's weights (any checkpoint of the same preset, e.g. a `gdsr weights`
  // file): fine-tuning, with a fresh AdamW and step 0. Not with resume.
  std::string init;
  // Data-parallel training (train/mpi_ranks.hpp): this process is rank `rank` of `ranks`;
  // a step covers frames_per_step frames on every rank, `allreduce_sum` sums a buffer over
  // all ranks in place (needed when ranks > 1). Give checkpoint paths on one rank only.
  int rank = 0, ranks = 1;
  std::function<void(std::vector<double>&)> allreduce_sum;
};

// Throws a one-line gdsr::Error naming the option when a value is out of range (epochs,
// max_steps, frames_per_step, lr, weight decay, schedule, loss weights, patches).
// train_gdsr calls it first, so nothing is written for bad options.
void validate_train_options(const TrainOptions& opt);

// Throws a one-line gdsr::Error naming opt.init when its weights do not fit opt.model (another
// preset, a missing or corrupt file). Reads the file; run it before the run folder is made.
void check_init_weights(const TrainOptions& opt);

struct TrainLog {
  int64_t step = 0, total_steps = 0;
  int epoch = 0;
  double loss = 0, coarse = 0, fine = 0;  // total and the two weighted parts
  double lambda_c = 1, lambda_w = 1, lr = 0;
  double seconds = 0;                   // wall time of this step
  double grad_norm = 0;                 // L2 norm of the (averaged) gradient of all parameters
  double allreduce_seconds = 0;         // wall time of the sum over ranks (0 with one rank)
  std::map<std::string, double> terms;  // unweighted loss terms (means over the step's frames)
  bool checkpointed = false;            // a checkpoint was written after this step
  bool validated = false;               // val_* hold the validation figures of this step
  double val_loss = 0, val_coarse = 0, val_fine = 0;  // means over the validation frames
  // mm, mean over the validation frames' patch vertices of |G - HR| (in a roll-out) and, as the
  // yardstick, of |upsampled LR input - HR| at the same vertices; NaN without patches (--no-fine)
  double val_vertex_mm = 0, val_upsample_mm = 0;
  // the same patches' normal-map SSIM over garment pixels (gdsr::ssim_score), GDSR and the
  // upsampled LR; NaN without patches
  double val_ssim = 0, val_upsample_ssim = 0;
};

struct TrainResult {
  int64_t steps = 0;
  double first_loss = 0, last_loss = 0;              // single-step totals
  double first_epoch_mean = 0, last_epoch_mean = 0;  // mean total over the first / last epoch
  double seconds_per_step = 0;
  int64_t parameters = 0;
  std::string checkpoint, best_checkpoint;  // "" when not written
  double best = 0;                           // the figure of the best checkpoint
};

TrainResult train_gdsr(const std::vector<const Dataset*>& data, const TrainOptions& opt,
                       const std::function<void(const TrainLog&)>& log = {});

}  // namespace gdsr

#include "train/trainer.hpp"

#include "gdsr/error.hpp"

#include "autograd/autograd.hpp"
#include "gdsr/data/frame_input.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "nn/adamw.hpp"
#include "nn/checkpoint.hpp"
#include "gdsr/model/model_checkpoint.hpp"
#include "nn/feature_loss.hpp"
#include "nn/lr_schedule.hpp"
#include "nn/vgg.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

namespace gdsr {
namespace {

// Everything about one dataset that does not change from step to step.
struct Sequence {
  const Dataset* d = nullptr;
  GarmentGraph graph;
  MeshTopology lr_topo;
  std::vector<Points3> lr_truth;  // HR ground truth downsampled to LR topology, per frame
  std::unique_ptr<BodyQuery> body;
  std::unique_ptr<PatchSampler> sampler;
};

Sequence prepare(const Dataset& d, const TrainOptions& opt) {
  Sequence s;
  s.d = &d;
  s.graph = build_graph(d.lr);
  s.lr_topo = make_topology(d.lr);
  s.lr_truth.reserve(d.hr_frames.size());
  for (const Points3& g : d.hr_frames) s.lr_truth.push_back(downsample(d.corr, g));
  s.body = make_body_query(d);
  if (opt.fine) s.sampler = std::make_unique<PatchSampler>(d.raster, d.hr, d.corr.hr_from_lr.tri, opt.patches);
  return s;
}

bool finite_gradients(const std::vector<ag::Tensor<float>>& params) {
  for (const auto& p : params)
    for (float g : p.grad())
      if (!std::isfinite(g)) return false;
  return true;
}

// Everything a training run carries from step to step.
struct TrainState {
  std::vector<Sequence> seqs;
  std::vector<std::pair<int, int>> frames;  // (sequence, t), t >= 2: all training frames
  std::vector<std::pair<int, int>> order;   // this epoch's shuffled frames
  std::unique_ptr<GDSR<float>> model;
  std::unique_ptr<nn::AdamW<float>> adam;
  std::unique_ptr<nn::VGG19Features<float>> vgg;
  ImageLossFn<float> image_loss;  // empty: no VGG term
  std::vector<ag::Tensor<float>> params;
  std::mt19937_64 rng;  // frame order and patches
  nn::Rng noise{0};     // training noise on the history (seeded in start_training)
  int64_t step = 0, first_step = 0, total = 0, per_epoch = 0;
  int current_epoch = -1;
  double epoch_sum = 0;  // loss summed over the current epoch
  int64_t epoch_count = 0;
  TrainResult res;
  std::chrono::steady_clock::time_point start;
};

// Sequences, model, AdamW (resumed from opt.resume), VGG, the step range and the RNGs.
void start_training(TrainState& s, const std::vector<const Dataset*>& data, const TrainOptions& opt) {
  if (data.empty()) gdsr::fail("train", "no dataset given");
  for (const Dataset* d : data) {
    if (d->lr_frames.size() < 3) gdsr::fail("train", "a dataset needs at least 3 frames");
    s.seqs.push_back(prepare(*d, opt));
    for (int t = 2; t < static_cast<int>(d->lr_frames.size()); ++t)
      s.frames.push_back({static_cast<int>(s.seqs.size()) - 1, t});
  }
  s.model = std::make_unique<GDSR<float>>(opt.model);
  nn::AdamWOptions ao;
  ao.lr = opt.lr;
  ao.weight_decay = opt.weight_decay;
  ao.amsgrad = opt.amsgrad;
  s.adam = std::make_unique<nn::AdamW<float>>(s.model->named_parameters(), ao);
  if (!opt.resume.empty()) s.step = nn::load_checkpoint(opt.resume, *s.model, s.adam.get()).step;

  if (opt.fine && opt.vgg && opt.loss.f_vgg.on && opt.loss.f_normal_map.on) {
    s.vgg = opt.vgg_dir.empty() ? std::make_unique<nn::VGG19Features<float>>()
                                : std::make_unique<nn::VGG19Features<float>>(opt.vgg_dir);
    s.image_loss = [vgg = s.vgg.get()](const ag::Tensorf& pred, const ag::Tensorf& target) {
      return nn::vgg_loss(*vgg, pred, target);
    };
  }
  s.per_epoch = static_cast<int64_t>(s.frames.size());
  s.total = s.per_epoch * opt.epochs;
  if (opt.max_steps >= 0) s.total = std::min(s.total, s.step + opt.max_steps);
  s.rng.seed(opt.seed + static_cast<uint64_t>(s.step));
  s.noise = nn::Rng(opt.seed * 7919 + 1 + static_cast<uint64_t>(s.step));
  s.params = s.model->parameters();
  s.res.parameters = s.model->num_parameters();
  s.first_step = s.step;
  s.start = std::chrono::steady_clock::now();
}

// Closes the epoch statistics (first and last epoch means).
void close_epoch(TrainState& s) {
  if (s.current_epoch < 0 || s.epoch_count == 0) return;
  const double mean = s.epoch_sum / static_cast<double>(s.epoch_count);
  if (s.current_epoch == static_cast<int>(s.first_step / s.per_epoch)) s.res.first_epoch_mean = mean;
  s.res.last_epoch_mean = mean;
}

// The (sequence, t) of this step; a new epoch reshuffles the frames.
std::pair<int, int> next_frame(TrainState& s) {
  const int epoch = static_cast<int>(s.step / s.per_epoch);
  if (epoch != s.current_epoch) {
    close_epoch(s);
    s.epoch_sum = 0;
    s.epoch_count = 0;
    s.current_epoch = epoch;
    s.order = s.frames;
    std::shuffle(s.order.begin(), s.order.end(), s.rng);
  }
  return s.order[static_cast<size_t>(s.step % s.per_epoch)];
}

std::string last_good(const TrainState& s) {
  return s.res.checkpoint.empty() ? "" : "; last good checkpoint: " + s.res.checkpoint;
}

// One step on frame t of sequence si: forward, losses, finite checks, backward, AdamW.
// Throws before the parameters are touched when the loss or a gradient is not finite.
TrainLog train_step(TrainState& s, int si, int t, const TrainOptions& opt) {
  Sequence& seq = s.seqs[static_cast<size_t>(si)];
  const Dataset& d = *seq.d;
  const auto t0 = std::chrono::steady_clock::now();

  const FrameInput in = make_frame_input(d, t, seq.lr_truth[t - 1], seq.lr_truth[t - 2], seq.body.get());
  PatchBatch batch;
  HrRequest request;
  if (opt.fine) {
    batch = seq.sampler->sample(s.rng);
    request = hr_request_subset(d.corr, batch.vertices);
  }
  const Lambdas lambdas = opt.loss.schedule ? lambda_schedule(opt.loss, s.current_epoch) : Lambdas{1, 1};
  const nn::StepDecay decay{opt.lr, 0.5, opt.lr_halve_every, opt.lr_floor};
  decay.apply(*s.adam, s.step);

  const GdsrOutput<float> out = s.model->forward(seq.graph, in, opt.fine ? &request : nullptr, &s.noise);
  const CoarseLoss<float> coarse = coarse_loss(opt.loss, seq.lr_topo, out.C_hat, seq.lr_truth[t]);
  FineLoss<float> fine;
  if (opt.fine) fine = fine_loss(opt.loss, batch, out.G, d.hr_frames[t], s.image_loss);
  const ag::Tensorf loss = total_loss(lambdas, coarse.total, fine.total);

  TrainLog L;
  L.step = s.step + 1;
  L.total_steps = s.total;
  L.epoch = s.current_epoch;
  L.loss = loss.item();
  L.coarse = lambdas.coarse * coarse.total.item();
  L.fine = fine.total.defined() ? lambdas.fine * fine.total.item() : 0.0;
  L.lambda_c = lambdas.coarse;
  L.lambda_w = lambdas.fine;
  L.lr = s.adam->lr();
  L.terms = coarse.log();                   // keys c_position, c_normal, ...
  if (opt.fine) L.terms.merge(fine.log());  // f_position, f_vgg, ...

  const std::string at = "training stopped at step " + std::to_string(s.step + 1);
  if (!std::isfinite(L.loss))
    gdsr::fail(at, "the loss is " + std::to_string(L.loss) + " (coarse " + std::to_string(L.coarse) + ", fine " +
                       std::to_string(L.fine) + ")" + last_good(s));
  s.adam->zero_grad();
  loss.backward();
  if (!finite_gradients(s.params)) gdsr::fail(at, "a gradient is not finite" + last_good(s));
  s.adam->step();
  L.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return L;
}

void record_step(TrainState& s, const TrainLog& L) {
  ++s.step;
  if (s.res.steps == 0) s.res.first_loss = L.loss;
  s.res.last_loss = L.loss;
  ++s.res.steps;
  s.epoch_sum += L.loss;
  ++s.epoch_count;
}

void save_checkpoint(TrainState& s, const TrainOptions& opt) {
  if (opt.checkpoint.empty()) return;
  nn::save_checkpoint(opt.checkpoint, *s.model, s.adam.get(), s.step, checkpoint_metadata(opt.model));
  s.res.checkpoint = opt.checkpoint;
}

}  // namespace

TrainResult train_gdsr(const std::vector<const Dataset*>& data, const TrainOptions& opt,
                       const std::function<void(const TrainLog&)>& log) {
  TrainState s;
  start_training(s, data, opt);
  while (s.step < s.total) {
    const auto [si, t] = next_frame(s);
    const TrainLog L = train_step(s, si, t, opt);
    record_step(s, L);
    if (log) log(L);
    if (opt.checkpoint_every > 0 && s.step % opt.checkpoint_every == 0) save_checkpoint(s, opt);
  }
  close_epoch(s);
  save_checkpoint(s, opt);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - s.start).count();
  s.res.seconds_per_step = s.res.steps ? secs / static_cast<double>(s.res.steps) : 0.0;
  return s.res;
}

}  // namespace gdsr

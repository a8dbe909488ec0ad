#include "train/trainer.hpp"

#include "gdsr/error.hpp"

#include "autograd/autograd.hpp"
#include "gdsr/data/frame_input.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_checkpoint.hpp"
#include "nn/adamw.hpp"
#include "nn/checkpoint.hpp"
#include "nn/feature_loss.hpp"
#include "nn/lr_schedule.hpp"
#include "nn/vgg.hpp"
#include "train/detail_target.hpp"
#include "train/train_state.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
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
  if (d.lr_frames.size() < 3) gdsr::fail("train", "a dataset needs at least 3 frames");
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

// Everything a training run carries from step to step.
struct TrainState {
  std::vector<Sequence> seqs, val;
  std::vector<std::pair<int, int>> frames;  // (sequence, t), t >= 2: all training frames
  std::unique_ptr<GDSR<float>> model;
  std::unique_ptr<nn::AdamW<float>> adam;
  std::unique_ptr<nn::VGG19Features<float>> vgg;
  ImageLossFn<float> image_loss;  // empty: no VGG term
  std::vector<std::pair<std::string, ag::Tensor<float>>> named;
  std::mt19937_64 rng;  // frame order and one patch seed per frame
  nn::Rng noise{0};     // one seed per frame for the training noise on the history
  TrainProgress p;      // step, data position, best figure (the RNGs live above while running)
  std::string last_good;  // the newest checkpoint of this run on disk ("" = none)
  int64_t first_step = 0, total = 0;
  int stat_epoch = -1;   // epoch of epoch_sum / epoch_count
  double epoch_sum = 0;  // loss summed over the current epoch
  int64_t epoch_count = 0;
  bool first_epoch_closed = false;
  TrainResult res;
  std::chrono::steady_clock::time_point start;
};

void check_weight(const std::string& name, double w) {
  if (!std::isfinite(w) || w < 0) gdsr::fail("train", "loss weight " + name + " must be finite and >= 0, got " + std::to_string(w));
}

// The state of the RNGs and the data position from a checkpoint written by this trainer.
void restore_progress(TrainState& s, const nn::Checkpoint& ck, const std::string& path, const TrainOptions& opt) {
  const std::vector<std::string> given = s.p.data;
  nlohmann::json meta;
  try {
    meta = nlohmann::json::parse(ck.metadata);
  } catch (const std::exception&) {
    gdsr::fail(path, "checkpoint metadata is not JSON");
  }
  if (!meta.contains("trainer"))
    gdsr::fail(path, "holds no training state (data order, RNGs), so it cannot be resumed exactly");
  s.p = progress_from_json(meta["trainer"], path);
  if (s.p.step != ck.step) gdsr::fail(path, "training state is at another step than the checkpoint");
  for (size_t i = 0; i < std::max(given.size(), s.p.data.size()); ++i) {
    const std::string was = i < s.p.data.size() ? s.p.data[i] : "nothing", now = i < given.size() ? given[i] : "nothing";
    if (was != now)
      gdsr::fail(path, "was trained on other data: sequence " + std::to_string(i + 1) + " was '" + was +
                           "' (garment LR/HR vertices frames), the data given is '" + now + "'");
  }
  if (s.p.frames_per_epoch != static_cast<int64_t>(s.frames.size()))
    gdsr::fail(path, "was trained on " + std::to_string(s.p.frames_per_epoch) + " frames per epoch, the data given has " +
                         std::to_string(s.frames.size()));
  if (s.p.frames_per_step != opt.frames_per_step * opt.ranks)
    gdsr::fail(path, "was trained with " + std::to_string(s.p.frames_per_step) + " frames per step, not " +
                         std::to_string(opt.frames_per_step * opt.ranks) + " (frames per step x ranks)");
  for (const auto& [si, t] : s.p.order)
    if (si < 0 || si >= static_cast<int>(s.seqs.size()) || t < 2 ||
        t >= static_cast<int>(s.seqs[static_cast<size_t>(si)].d->lr_frames.size()))
      gdsr::fail(path, "training state names a frame the data given does not have");
  std::istringstream in(s.p.order_rng);
  in >> s.rng;
  if (!in) gdsr::fail(path, "training state: the frame-order RNG state does not parse");
  s.noise.set_state(s.p.noise);
}

// Sequences, model (from opt.init's weights), AdamW (resumed from opt.resume), VGG, the step range and the RNGs.
void start_training(TrainState& s, const std::vector<const Dataset*>& data, const TrainOptions& opt) {
  for (const Dataset* d : data) {
    s.seqs.push_back(prepare(*d, opt));
    for (int t = 2; t < static_cast<int>(d->lr_frames.size()); ++t)
      s.frames.push_back({static_cast<int>(s.seqs.size()) - 1, t});
  }
  for (const Dataset* d : opt.validation) s.val.push_back(prepare(*d, opt));
  s.model = std::make_unique<GDSR<float>>(opt.model);
  nn::AdamWOptions ao;
  ao.lr = opt.lr;
  ao.weight_decay = opt.weight_decay;
  ao.amsgrad = opt.amsgrad;
  s.adam = std::make_unique<nn::AdamW<float>>(s.model->named_parameters(), ao);
  s.p.frames_per_step = opt.frames_per_step * opt.ranks;
  s.p.frames_per_epoch = static_cast<int64_t>(s.frames.size());
  for (const Dataset* d : data)
    s.p.data.push_back(d->manifest.garment + " " + std::to_string(d->lr.V.rows()) + "/" +
                       std::to_string(d->hr.V.rows()) + " " + std::to_string(d->lr_frames.size()));
  s.rng.seed(opt.seed);
  s.noise = nn::Rng(opt.seed * 7919 + 1);
  if (!opt.init.empty()) nn::load_checkpoint(opt.init, *s.model, static_cast<nn::AdamW<float>*>(nullptr));
  if (!opt.resume.empty()) {
    const nn::Checkpoint ck = nn::load_checkpoint(opt.resume, *s.model, s.adam.get());
    restore_progress(s, ck, opt.resume, opt);
    s.last_good = opt.resume;
  }

  const int64_t frames = s.p.frames_per_epoch * opt.epochs, per_step = int64_t{opt.frames_per_step} * opt.ranks;
  if (frames < per_step)
    gdsr::fail("train", std::to_string(opt.epochs) + " epoch(s) of " + std::to_string(s.p.frames_per_epoch) +
                            " frames hold fewer frames than one step of " + std::to_string(per_step));
  s.total = frames / per_step;
  if (opt.max_steps > 0) s.total = std::min(s.total, opt.max_steps);
  if (s.p.step >= s.total)
    gdsr::fail(opt.resume, "is already at step " + std::to_string(s.p.step) + " of " + std::to_string(s.total) +
                               "; raise --epochs or --max-steps to train further");

  if (opt.fine && opt.vgg && opt.loss.f_vgg.on && opt.loss.f_normal_map.on) {
    s.vgg = opt.vgg_dir.empty() ? std::make_unique<nn::VGG19Features<float>>()
                                : std::make_unique<nn::VGG19Features<float>>(opt.vgg_dir);
    s.image_loss = [vgg = s.vgg.get()](const ag::Tensorf& pred, const ag::Tensorf& target) {
      return nn::vgg_loss(*vgg, pred, target);
    };
  }
  s.named = s.model->named_parameters();
  s.res.parameters = s.model->num_parameters();
  s.first_step = s.p.step;
  s.start = std::chrono::steady_clock::now();
}

// Closes the epoch statistics (first and last epoch means of this process).
void close_epoch(TrainState& s) {
  if (s.stat_epoch < 0 || s.epoch_count == 0) return;
  const double mean = s.epoch_sum / static_cast<double>(s.epoch_count);
  if (!s.first_epoch_closed) s.res.first_epoch_mean = mean;
  s.first_epoch_closed = true;
  s.res.last_epoch_mean = mean;
}

// The next training frame (sequence, t); a new epoch reshuffles the frames.
std::pair<int, int> next_frame(TrainState& s) {
  const int epoch = static_cast<int>(s.p.frame_pos / s.p.frames_per_epoch);
  if (epoch != s.p.epoch) {
    s.p.epoch = epoch;
    s.p.order = s.frames;
    std::shuffle(s.p.order.begin(), s.p.order.end(), s.rng);
  }
  return s.p.order[static_cast<size_t>(s.p.frame_pos++ % s.p.frames_per_epoch)];
}

std::string last_good(const TrainState& s) {
  return s.last_good.empty() ? "" : "; last good checkpoint: " + s.last_good;
}

struct FrameLoss {
  ag::Tensorf total;
  double coarse = 0, fine = 0;          // weighted parts
  std::map<std::string, double> terms;  // unweighted
  Points3 C_hat;                        // the corrected LR frame (the next frame's history in a roll-out)
  double vertex_m = 0, upsample_m = 0;  // validation only: mean |G - HR| and |upsampled LR - HR| on the patches
  double ssim = 0, upsample_ssim = 0;   // validation only: their patches' normal-map SSIM (garment pixels)
};

// Mean distance, metres, between rows `vertices` of `truth` and the rows of `predicted`
// (predicted row i is vertex vertices[i]; `all`: predicted holds every vertex).
double mean_distance_at(const Points3& predicted, const Points3& truth, const std::vector<int>& vertices, bool all) {
  double sum = 0;
  for (size_t i = 0; i < vertices.size(); ++i)
    sum += (predicted.row(all ? vertices[i] : static_cast<int>(i)) - truth.row(vertices[i])).norm();
  return vertices.empty() ? 0.0 : sum / static_cast<double>(vertices.size());
}

// The coarse losses of frames before t in an unrolled step (train_step with opt.unroll > 1).
struct EarlierCoarse {
  ag::Tensorf sum;  // their coarse totals, summed
  int frames = 0;
};

// Forward and losses of frame t of a sequence (noise and rng: training draws; nullptr noise
// for validation). history: the corrected history as tensors (values chat_tm1, chat_tm2) to
// differentiate through; earlier: coarse losses of the unrolled frames before t, averaged
// with frame t's into the coarse term.
FrameLoss frame_loss(TrainState& s, Sequence& seq, int t, const Points3& chat_tm1, const Points3& chat_tm2,
                     const Lambdas& lambdas, std::mt19937_64& rng, nn::Rng* noise, const TrainOptions& opt,
                     const HistoryTensors<float>* history = nullptr, const EarlierCoarse* earlier = nullptr) {
  const Dataset& d = *seq.d;
  const FrameInput in = make_frame_input(d, t, chat_tm1, chat_tm2, seq.body.get());
  PatchBatch batch;
  HrRequest request;
  if (opt.fine) {
    batch = seq.sampler->sample(rng);
    request = hr_request_subset(d.corr, batch.vertices);
  }
  const GdsrOutput<float> out = s.model->forward(seq.graph, in, opt.fine ? &request : nullptr, noise, nullptr, history);
  const CoarseLoss<float> coarse = coarse_loss(opt.loss, seq.lr_topo, out.C_hat, seq.lr_truth[t]);
  const ag::Tensorf coarse_total =
      earlier && earlier->frames > 0
          ? ag::mul_scalar(ag::add(coarse.total, earlier->sum), 1.0f / static_cast<float>(earlier->frames + 1))
          : coarse.total;
  FrameLoss f;
  f.C_hat = gdsr::to_points(out.C_hat);
  FineLoss<float> fine;
  if (opt.fine) {
    const Points3 target = opt.detail_target ? detail_target(d.corr, d.hr_frames[t], seq.lr_truth[t], f.C_hat,
                                                             batch.vertices, opt.model.frame_eps)
                                             : Points3();
    fine = fine_loss(opt.loss, batch, out.G, opt.detail_target ? target : d.hr_frames[t], s.image_loss);
  }
  f.total = total_loss(lambdas, coarse_total, fine.total);
  f.coarse = lambdas.coarse * coarse_total.item();
  f.fine = fine.total.defined() ? lambdas.fine * fine.total.item() : 0.0;
  f.terms = coarse.log();                   // keys c_position, c_normal, ...
  if (opt.fine) f.terms.merge(fine.log());  // f_position, f_vgg, ...
  if (opt.fine && !noise) {
    const Points3 G = gdsr::to_points(out.G), up = upsample(d.corr, d.lr_frames[t]);
    f.vertex_m = mean_distance_at(G, d.hr_frames[t], batch.vertices, false);
    f.upsample_m = mean_distance_at(up, d.hr_frames[t], batch.vertices, true);
    const auto rows = [&](const Points3& X) {
      Points3 out_rows(static_cast<Eigen::Index>(batch.vertices.size()), 3);
      for (size_t i = 0; i < batch.vertices.size(); ++i)
        out_rows.row(static_cast<Eigen::Index>(i)) = X.row(batch.vertices[i]);
      return out_rows;
    };
    const Points3 truth = rows(d.hr_frames[t]);
    f.ssim = patch_normal_map_ssim(batch, G, truth);
    f.upsample_ssim = patch_normal_map_ssim(batch, rows(up), truth);
  }
  return f;
}

std::string value_text(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "+inf" : "-inf";
  return std::to_string(v);
}

// Names the first non-finite loss term (then the weighted total) of a frame.
void check_finite_loss(const TrainState& s, const FrameLoss& f, int si, int t) {
  const std::string at = "training stopped at step " + std::to_string(s.p.step + 1);
  const std::string frame = " (dataset " + std::to_string(si) + " frame " + std::to_string(t) + ")";
  for (const auto& [name, v] : f.terms)
    if (!std::isfinite(v))
      gdsr::fail(at, "loss term " + name + " is " + value_text(v) + frame + last_good(s));
  const double total = f.total.item();
  if (!std::isfinite(total))
    gdsr::fail(at, "the weighted loss total is " + value_text(total) + frame + last_good(s));
}

// L2 norm of all gradients; throws naming the first parameter with a non-finite gradient.
double checked_grad_norm(const TrainState& s) {
  double sum = 0;
  for (const auto& [name, p] : s.named)
    for (float g : p.grad()) {
      if (!std::isfinite(g))
        gdsr::fail("training stopped at step " + std::to_string(s.p.step + 1),
                   "the gradient of parameter " + name + " is not finite" + last_good(s));
      sum += static_cast<double>(g) * g;
    }
  return std::sqrt(sum);
}

// The gradients of a step's frames summed in double, frame by frame (each frame's float
// gradient computed from zero), then over the ranks: one process with K frames per step and
// K ranks with one frame each add the same float gradients in the same pairs.
struct GradientSum {
  std::vector<std::vector<double>> g;  // per parameter; empty: no gradient yet
  explicit GradientSum(size_t n) : g(n) {}
  // Moves the parameters' gradients of one frame into the sum.
  void take(const TrainState& s) {
    for (size_t i = 0; i < s.named.size(); ++i) {
      auto& p = s.named[i].second;
      if (!p.has_grad()) continue;
      if (g[i].empty()) g[i].assign(static_cast<size_t>(p.numel()), 0.0);
      const auto& pg = p.grad();
      for (size_t k = 0; k < pg.size(); ++k) g[i][k] += pg[k];
      p.node().zero_grad();
    }
  }
  // Writes the sum back as the parameters' gradients.
  void give(const TrainState& s) const {
    for (size_t i = 0; i < s.named.size(); ++i) {
      auto& grad = s.named[i].second.node().grad;
      grad.assign(g[i].begin(), g[i].end());
    }
  }
};

// Sums the step's log figures and gradients over the ranks; a parameter without a gradient
// on every rank keeps none, as in one process. Then checks the summed loss terms.
void reduce_over_ranks(TrainState& s, TrainLog& L, GradientSum& sum, const TrainOptions& opt) {
  std::vector<double> buf = {L.loss, L.coarse, L.fine};
  for (const auto& [name, v] : L.terms) buf.push_back(v);
  for (size_t i = 0; i < s.named.size(); ++i) {
    buf.push_back(sum.g[i].empty() ? 0.0 : 1.0);
    if (sum.g[i].empty())
      buf.insert(buf.end(), static_cast<size_t>(s.named[i].second.numel()), 0.0);
    else
      buf.insert(buf.end(), sum.g[i].begin(), sum.g[i].end());
  }
  const auto t0 = std::chrono::steady_clock::now();
  opt.allreduce_sum(buf);
  L.allreduce_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  size_t j = 0;
  L.loss = buf[j++];
  L.coarse = buf[j++];
  L.fine = buf[j++];
  for (auto& [name, v] : L.terms) v = buf[j++];
  for (size_t i = 0; i < s.named.size(); ++i) {
    const bool any = buf[j++] > 0;
    const size_t n = static_cast<size_t>(s.named[i].second.numel());
    if (any)
      sum.g[i].assign(buf.begin() + static_cast<std::ptrdiff_t>(j), buf.begin() + static_cast<std::ptrdiff_t>(j + n));
    else
      sum.g[i].clear();
    j += n;
  }
  const std::string at = "training stopped at step " + std::to_string(s.p.step + 1);
  for (const auto& [name, v] : L.terms)
    if (!std::isfinite(v)) gdsr::fail(at, "loss term " + name + " is " + value_text(v) + " on a rank" + last_good(s));
  if (!std::isfinite(L.loss)) gdsr::fail(at, "the weighted loss total is " + value_text(L.loss) + last_good(s));
}

// The loss of training frame t through a roll-out (opt.unroll > 1): frames t0 = max(t - unroll
// + 1, 2) .. t are run with gradient, each one's corrected history being the outputs of the
// frames before it as tensors, so the loss reaches back through the history. The history of
// frame t0 is what it would be without unrolling (teacher forcing or push-forward).
FrameLoss unrolled_loss(TrainState& s, Sequence& seq, int t, const Lambdas& lambdas, std::mt19937_64& rng,
                        nn::Rng& noise, const TrainOptions& opt) {
  const Dataset& d = *seq.d;
  const int t0 = std::max(t - opt.unroll + 1, 2);
  std::vector<Points3> pred;
  int first = t0;
  const std::vector<Points3>* before = &seq.lr_truth;  // teacher forcing
  if (opt.rollout_history > 0) {
    first = std::max(t0 - opt.rollout_history, 0);
    before = opt.rollout_from_truth ? &seq.lr_truth : nullptr;
    pred = corrected_rollout(*s.model, seq.graph, d, seq.body.get(), first, t0 - first, before);
  }
  Points3 h1 = rollout_history(d, pred, first, t0, 1, before), h2 = rollout_history(d, pred, first, t0, 2, before);
  HistoryTensors<float> history{to_tensor<float>(h1), to_tensor<float>(h2)};
  EarlierCoarse earlier;
  for (int k = t0; k < t; ++k, ++earlier.frames) {
    const FrameInput in = make_frame_input(d, k, h1, h2, seq.body.get());
    const GdsrOutput<float> out = s.model->forward(seq.graph, in, nullptr, &noise, nullptr, &history);
    const ag::Tensorf c = coarse_loss(opt.loss, seq.lr_topo, out.C_hat, seq.lr_truth[k]).total;
    earlier.sum = earlier.frames == 0 ? c : ag::add(earlier.sum, c);
    h2 = std::move(h1);
    h1 = gdsr::to_points(out.C_hat);
    history = HistoryTensors<float>{out.C_hat, history.Chat_tm1};
  }
  return frame_loss(s, seq, t, h1, h2, lambdas, rng, &noise, opt, &history, &earlier);
}

// One optimizer step on the next frames_per_step x ranks frames (this rank takes every
// ranks-th one): forward, losses, finite checks, backward, the gradient sum, AdamW. Every
// frame draws one seed from each main RNG stream for its patches and noise whichever rank
// computes it, so the streams do not depend on the number of ranks. Throws before the
// parameters are touched when a loss term or a gradient is not finite.
TrainLog train_step(TrainState& s, const TrainOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const nn::StepDecay decay{opt.lr, 0.5, opt.lr_halve_every, opt.lr_floor};
  decay.apply(*s.adam, s.p.step);
  s.adam->zero_grad();

  TrainLog L;
  const int K = opt.frames_per_step * opt.ranks;
  const double inv = 1.0 / K;
  GradientSum sum(K > 1 ? s.named.size() : 0);  // one frame: its gradient stays in place
  for (int k = 0; k < K; ++k) {
    const auto [si, t] = next_frame(s);
    if (k == 0) L.epoch = s.p.epoch;
    const Lambdas lambdas = opt.loss.schedule ? lambda_schedule(opt.loss, L.epoch) : Lambdas{1, 1};
    L.lambda_c = lambdas.coarse;
    L.lambda_w = lambdas.fine;
    std::mt19937_64 patch_rng(s.rng());
    nn::Rng noise(s.noise.next());
    if (k % opt.ranks != opt.rank) continue;
    Sequence& seq = s.seqs[static_cast<size_t>(si)];
    FrameLoss f;
    if (opt.unroll > 1) {
      f = unrolled_loss(s, seq, t, lambdas, patch_rng, noise, opt);
    } else if (opt.rollout_history > 0) {  // push-forward: the history is the model's own, from a roll-out
      const int first = std::max(t - opt.rollout_history, 0);
      const std::vector<Points3>* before = opt.rollout_from_truth ? &seq.lr_truth : nullptr;
      const std::vector<Points3> pred =
          corrected_rollout(*s.model, seq.graph, *seq.d, seq.body.get(), first, t - first, before);
      f = frame_loss(s, seq, t, rollout_history(*seq.d, pred, first, t, 1, before),
                     rollout_history(*seq.d, pred, first, t, 2, before), lambdas, patch_rng, &noise, opt);
    } else {  // teacher forcing
      f = frame_loss(s, seq, t, seq.lr_truth[t - 1], seq.lr_truth[t - 2], lambdas, patch_rng, &noise, opt);
    }
    check_finite_loss(s, f, si, t);
    L.loss += inv * f.total.item();
    L.coarse += inv * f.coarse;
    L.fine += inv * f.fine;
    for (const auto& [name, v] : f.terms) L.terms[name] += inv * v;
    if (K == 1) {
      f.total.backward();
    } else {
      (f.total * static_cast<float>(inv)).backward();
      sum.take(s);
    }
  }
  if (opt.ranks > 1) reduce_over_ranks(s, L, sum, opt);
  if (K > 1) sum.give(s);
  L.step = s.p.step + 1;
  L.total_steps = s.total;
  L.lr = s.adam->lr();
  L.grad_norm = checked_grad_norm(s);
  s.adam->step();
  L.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return L;
}

void record_step(TrainState& s, const TrainLog& L) {
  ++s.p.step;
  if (s.res.steps == 0) s.res.first_loss = L.loss;
  s.res.last_loss = L.loss;
  ++s.res.steps;
  if (L.epoch != s.stat_epoch) {
    close_epoch(s);
    s.epoch_sum = 0;
    s.epoch_count = 0;
    s.stat_epoch = L.epoch;
  }
  s.epoch_sum += L.loss;
  ++s.epoch_count;
  s.p.interval_sum += L.loss;
  ++s.p.interval_count;
}

// Mean losses over every frame of a roll-out of each validation clip from its frame 0 (the
// history is the model's own, as in `gdsr infer`): no gradient, no noise, patches from a
// fixed seed (the same patches at every validation).
void validate(TrainState& s, TrainLog& L, const TrainOptions& opt) {
  if (s.val.empty()) return;
  ag::NoGradGuard no_grad;
  std::mt19937_64 rng(opt.seed + 0x5eed);
  const Lambdas lambdas = opt.loss.schedule ? lambda_schedule(opt.loss, L.epoch) : Lambdas{1, 1};
  double total = 0, coarse = 0, fine = 0, vertex = 0, upsampled = 0, ssim = 0, upsampled_ssim = 0;
  int n = 0;
  for (Sequence& seq : s.val) {
    std::vector<Points3> pred;  // a roll-out from frame 0, as `gdsr infer` runs
    for (int t = 0; t < static_cast<int>(seq.d->lr_frames.size()); ++t, ++n) {
      FrameLoss f = frame_loss(s, seq, t, rollout_history(*seq.d, pred, 0, t, 1), rollout_history(*seq.d, pred, 0, t, 2),
                               lambdas, rng, nullptr, opt);
      pred.push_back(std::move(f.C_hat));
      total += f.total.item();
      coarse += f.coarse;
      fine += f.fine;
      vertex += f.vertex_m;
      upsampled += f.upsample_m;
      ssim += f.ssim;
      upsampled_ssim += f.upsample_ssim;
    }
  }
  L.validated = true;
  L.val_loss = total / n;
  L.val_coarse = coarse / n;
  L.val_fine = fine / n;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  L.val_vertex_mm = opt.fine ? 1000 * vertex / n : nan;
  L.val_upsample_mm = opt.fine ? 1000 * upsampled / n : nan;
  L.val_ssim = opt.fine ? ssim / n : nan;
  L.val_upsample_ssim = opt.fine ? upsampled_ssim / n : nan;
}

void check_finite_parameters(const TrainState& s) {
  for (const auto& [name, p] : s.named)
    for (float v : p.values())
      if (!std::isfinite(v))
        gdsr::fail("training stopped at step " + std::to_string(s.p.step),
                   "parameter " + name + " is not finite; not saved" + last_good(s));
}

void write_state(TrainState& s, const std::string& path, const TrainOptions& opt) {
  std::ostringstream rng;
  rng << s.rng;
  s.p.order_rng = rng.str();
  s.p.noise = s.noise.state();
  nlohmann::json meta = nlohmann::json::parse(checkpoint_metadata(opt.model));
  meta["trainer"] = progress_to_json(s.p);
  nn::save_checkpoint(path, *s.model, s.adam.get(), s.p.step, meta.dump());
}

// Before a checkpoint: the finite check, the validation figures and whether this one is the
// best so far (its figure the lowest yet).
bool prepare_checkpoint(TrainState& s, TrainLog& L, const TrainOptions& opt) {
  check_finite_parameters(s);
  validate(s, L, opt);
  const double figure =
      L.validated ? L.val_loss : s.p.interval_sum / static_cast<double>(std::max<int64_t>(1, s.p.interval_count));
  const bool best = !opt.best_checkpoint.empty() && std::isfinite(figure) && (!s.p.has_best || figure < s.p.best);
  if (best) {
    s.p.has_best = true;
    s.p.best = figure;
    s.res.best = figure;
  }
  s.p.interval_sum = 0;
  s.p.interval_count = 0;
  L.checkpointed = true;
  return best;
}

// The last good checkpoint and, when `best`, the best one.
void write_checkpoints(TrainState& s, bool best, const TrainOptions& opt) {
  if (best) {
    write_state(s, opt.best_checkpoint, opt);
    s.res.best_checkpoint = opt.best_checkpoint;
  }
  if (!opt.checkpoint.empty()) {
    write_state(s, opt.checkpoint, opt);
    s.res.checkpoint = opt.checkpoint;
    s.last_good = opt.checkpoint;
  }
}

}  // namespace

void check_init_weights(const TrainOptions& opt) {
  if (opt.init.empty()) return;
  GDSR<float> probe(opt.model);
  nn::load_checkpoint(opt.init, probe, static_cast<nn::AdamW<float>*>(nullptr));
}

void validate_train_options(const TrainOptions& opt) {
  if (opt.epochs <= 0) gdsr::fail("train", "--epochs must be positive, got " + std::to_string(opt.epochs));
  if (opt.max_steps == 0 || opt.max_steps < -1)
    gdsr::fail("train", "--max-steps must be positive, got " + std::to_string(opt.max_steps));
  if (opt.ranks <= 0 || opt.rank < 0 || opt.rank >= opt.ranks)
    gdsr::fail("train", "rank " + std::to_string(opt.rank) + " of " + std::to_string(opt.ranks) + " is not valid");
  if (opt.ranks > 1 && !opt.allreduce_sum) gdsr::fail("train", "several ranks need an all-reduce");
  if (opt.frames_per_step <= 0)
    gdsr::fail("train", "--frames-per-step must be positive, got " + std::to_string(opt.frames_per_step));
  if (!opt.init.empty() && !opt.resume.empty())
    gdsr::fail("train", "--init starts a new run from a model's weights and --resume continues one: give one");
  if (opt.rollout_history < 0 || opt.rollout_history > 64)
    gdsr::fail("train", "--rollout-history must be 0 (teacher forcing) to 64 frames, got " +
                            std::to_string(opt.rollout_history));
  if (opt.unroll < 1 || opt.unroll > 64)
    gdsr::fail("train", "--unroll must be 1 (off) to 64 frames, got " + std::to_string(opt.unroll));
  if (opt.rollout_from_truth && opt.rollout_history == 0)
    gdsr::fail("train",
               "--rollout-from-truth needs --rollout-history K > 0 (without it the history is the truth already)");
  if (!std::isfinite(opt.lr) || opt.lr <= 0) gdsr::fail("train", "--lr must be finite and > 0, got " + std::to_string(opt.lr));
  if (!std::isfinite(opt.lr_floor) || opt.lr_floor < 0) gdsr::fail("train", "the lr floor must be finite and >= 0");
  if (opt.lr_halve_every <= 0)
    gdsr::fail("train", "--lr-halve-every must be positive, got " + std::to_string(opt.lr_halve_every));
  if (!std::isfinite(opt.weight_decay) || opt.weight_decay < 0)
    gdsr::fail("train", "the weight decay must be finite and >= 0");
  if (opt.checkpoint_every < 0)
    gdsr::fail("train", "--checkpoint-every must be >= 0, got " + std::to_string(opt.checkpoint_every));
  if (opt.fine && (opt.patches.count <= 0 || opt.patches.size <= 0))
    gdsr::fail("train", "--patches and --patch-size must be positive");
  const LossConfig& c = opt.loss;
  const std::pair<const char*, const LossTerm*> terms[] = {
      {"c_position", &c.c_position}, {"c_normal", &c.c_normal},         {"c_strain", &c.c_strain},
      {"c_smooth", &c.c_smooth},     {"c_dihedral", &c.c_dihedral},     {"f_position", &c.f_position},
      {"f_normal_map", &c.f_normal_map}, {"f_vgg", &c.f_vgg},           {"f_image_l1", &c.f_image_l1},
      {"f_strain", &c.f_strain},     {"f_smooth", &c.f_smooth}};
  for (const auto& [name, term] : terms) check_weight(name, term->weight);
  for (const auto& [name, w] : {std::pair<const char*, double>{"lambda_c_start", c.lambda_c_start},
                                {"lambda_w_start", c.lambda_w_start}, {"lambda_c_end", c.lambda_c_end},
                                {"lambda_w_end", c.lambda_w_end}, {"lambda_step", c.lambda_step}})
    check_weight(name, w);
}

TrainResult train_gdsr(const std::vector<const Dataset*>& data, const TrainOptions& opt,
                       const std::function<void(const TrainLog&)>& log) {
  validate_train_options(opt);
  if (data.empty()) gdsr::fail("train", "no dataset given");
  TrainState s;
  start_training(s, data, opt);
  while (s.p.step < s.total) {
    TrainLog L = train_step(s, opt);
    record_step(s, L);
    // The log sees a step before its checkpoint does: a kill in between leaves a log that
    // runs ahead of the checkpoint (the resumed run drops those rows), never one with a gap.
    const bool save = (!opt.checkpoint.empty() || !opt.best_checkpoint.empty()) &&
                      (s.p.step == s.total || (opt.checkpoint_every > 0 && s.p.step % opt.checkpoint_every == 0));
    const bool best = save && prepare_checkpoint(s, L, opt);
    if (log) log(L);
    if (save) write_checkpoints(s, best, opt);
  }
  close_epoch(s);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - s.start).count();
  s.res.seconds_per_step = s.res.steps ? secs / static_cast<double>(s.res.steps) : 0.0;
  return s.res;
}

}  // namespace gdsr

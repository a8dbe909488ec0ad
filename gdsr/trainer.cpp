#include "gdsr/trainer.hpp"

#include "autograd/autograd.hpp"
#include "gdsr/frame_input.hpp"
#include "gdsr/gdsr_model.hpp"
#include "nn/adamw.hpp"
#include "nn/checkpoint.hpp"
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

}  // namespace

std::string checkpoint_metadata(const ModelConfig& cfg) {
  nlohmann::json j;
  j["kind"] = "gdsr-model";
  j["model_config"] = model_config_to_json_text(cfg);
  return j.dump();
}

ModelConfig config_from_checkpoint(const std::string& path) {
  const nn::Checkpoint ck = nn::read_checkpoint(path);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ck.metadata);
  } catch (const std::exception&) {
    throw std::runtime_error(path + ": checkpoint metadata is not JSON");
  }
  if (!j.contains("model_config")) throw std::runtime_error(path + ": not a GDSR model checkpoint (no model_config)");
  return model_config_from_json_text(j["model_config"].get<std::string>(), path);
}

TrainResult train_gdsr(const std::vector<const Dataset*>& data, const TrainOptions& opt,
                       const std::function<void(const TrainLog&)>& log) {
  if (data.empty()) throw std::runtime_error("train: no dataset given");
  std::vector<Sequence> seqs;
  std::vector<std::pair<int, int>> frames;  // (sequence, t)
  for (const Dataset* d : data) {
    if (d->lr_frames.size() < 3) throw std::runtime_error("train: a dataset needs at least 3 frames");
    seqs.push_back(prepare(*d, opt));
    for (int t = 2; t < static_cast<int>(d->lr_frames.size()); ++t)
      frames.push_back({static_cast<int>(seqs.size()) - 1, t});
  }

  GDSR<float> model(opt.model);
  nn::AdamWOptions ao;
  ao.lr = opt.lr;
  ao.weight_decay = opt.weight_decay;
  ao.amsgrad = opt.amsgrad;
  nn::AdamW<float> adam(model.named_parameters(), ao);
  const nn::StepDecay decay{opt.lr, 0.5, opt.lr_halve_every, opt.lr_floor};
  int64_t step = 0;
  if (!opt.resume.empty()) step = nn::load_checkpoint(opt.resume, model, &adam).step;

  std::unique_ptr<nn::VGG19Features<float>> vgg;
  ImageLossFn<float> image_loss;
  if (opt.fine && opt.vgg && opt.loss.f_vgg.on && opt.loss.f_normal_map.on) {
    vgg = opt.vgg_dir.empty() ? std::make_unique<nn::VGG19Features<float>>()
                              : std::make_unique<nn::VGG19Features<float>>(opt.vgg_dir);
    image_loss = [&vgg](const ag::Tensorf& pred, const ag::Tensorf& target) {
      return nn::vgg_loss(*vgg, pred, target);
    };
  }

  const int64_t per_epoch = static_cast<int64_t>(frames.size());
  int64_t total = per_epoch * opt.epochs;
  if (opt.max_steps >= 0) total = std::min(total, step + opt.max_steps);
  std::mt19937_64 rng(opt.seed + static_cast<uint64_t>(step));
  nn::Rng noise(opt.seed * 7919 + 1 + static_cast<uint64_t>(step));
  const auto params = model.parameters();

  TrainResult res;
  res.parameters = model.num_parameters();
  double epoch_sum = 0;
  int64_t epoch_count = 0;
  int current_epoch = -1;
  std::vector<std::pair<int, int>> order;
  const auto t_start = std::chrono::steady_clock::now();
  const int64_t first_step = step;

  auto save = [&](int64_t at) {
    if (opt.checkpoint.empty()) return;
    nn::save_checkpoint(opt.checkpoint, model, &adam, at, checkpoint_metadata(opt.model));
    res.checkpoint = opt.checkpoint;
  };

  while (step < total) {
    const int epoch = static_cast<int>(step / per_epoch);
    if (epoch != current_epoch) {
      if (current_epoch >= 0) {
        if (current_epoch == static_cast<int>(first_step / per_epoch)) res.first_epoch_mean = epoch_sum / epoch_count;
        res.last_epoch_mean = epoch_sum / epoch_count;
      }
      epoch_sum = 0;
      epoch_count = 0;
      current_epoch = epoch;
      order = frames;
      std::shuffle(order.begin(), order.end(), rng);
    }
    const auto [si, t] = order[static_cast<size_t>(step % per_epoch)];
    Sequence& s = seqs[static_cast<size_t>(si)];
    const Dataset& d = *s.d;
    const auto t0 = std::chrono::steady_clock::now();

    const FrameInput in = make_frame_input(d, t, s.lr_truth[t - 1], s.lr_truth[t - 2], s.body.get());
    PatchBatch batch;
    HrRequest request;
    if (opt.fine) {
      batch = s.sampler->sample(rng);
      request = hr_request_subset(d.corr, batch.vertices);
    }
    const Lambdas lambdas = opt.loss.schedule ? lambda_schedule(opt.loss, epoch) : Lambdas{1, 1};
    decay.apply(adam, step);

    const GdsrOutput<float> out = model.forward(s.graph, in, opt.fine ? &request : nullptr, &noise);
    const CoarseLoss<float> coarse = coarse_loss(opt.loss, s.lr_topo, out.C_hat, s.lr_truth[t]);
    FineLoss<float> fine;
    if (opt.fine) fine = fine_loss(opt.loss, batch, out.G, d.hr_frames[t], image_loss);
    const ag::Tensorf loss = total_loss(lambdas, coarse.total, fine.total);
    const double value = loss.item();

    TrainLog L;
    L.step = step + 1;
    L.total_steps = total;
    L.epoch = epoch;
    L.loss = value;
    L.coarse = lambdas.coarse * coarse.total.item();
    L.fine = fine.total.defined() ? lambdas.fine * fine.total.item() : 0.0;
    L.lambda_c = lambdas.coarse;
    L.lambda_w = lambdas.fine;
    L.lr = adam.lr();
    L.terms = coarse.log();  // keys c_position, c_normal, ...
    if (opt.fine) L.terms.merge(fine.log());  // f_position, f_vgg, ...

    if (!std::isfinite(value))
      throw std::runtime_error("training stopped at step " + std::to_string(step + 1) + ": the loss is " +
                               std::to_string(value) + " (coarse " + std::to_string(L.coarse) + ", fine " +
                               std::to_string(L.fine) + ")" +
                               (res.checkpoint.empty() ? "" : "; last good checkpoint: " + res.checkpoint));
    adam.zero_grad();
    loss.backward();
    if (!finite_gradients(params))
      throw std::runtime_error("training stopped at step " + std::to_string(step + 1) +
                               ": a gradient is not finite" +
                               (res.checkpoint.empty() ? "" : "; last good checkpoint: " + res.checkpoint));
    adam.step();
    ++step;

    L.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (res.steps == 0) res.first_loss = value;
    res.last_loss = value;
    ++res.steps;
    epoch_sum += value;
    ++epoch_count;
    if (log) log(L);
    if (opt.checkpoint_every > 0 && step % opt.checkpoint_every == 0) save(step);
  }
  if (epoch_count > 0) {
    if (current_epoch == static_cast<int>(first_step / per_epoch)) res.first_epoch_mean = epoch_sum / epoch_count;
    res.last_epoch_mean = epoch_sum / epoch_count;
  }
  save(step);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  res.seconds_per_step = res.steps ? secs / static_cast<double>(res.steps) : 0.0;
  return res;
}

}  // namespace gdsr

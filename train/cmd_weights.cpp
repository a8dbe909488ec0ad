// gdsr weights: a training checkpoint's model weights alone (float32, no optimizer state, no
// training state), the form a trained model is shipped in (models/). `gdsr infer` loads it
// like any checkpoint; it cannot be resumed.
#include "gdsr/cli/commands.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_checkpoint.hpp"
#include "nn/checkpoint.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

namespace {

struct WeightsArgs {
  std::string model, out;
};

void run_weights(const WeightsArgs& a) {
  // Loading into the model checks every parameter's name, dtype and shape.
  const gdsr::ModelConfig cfg = gdsr::config_from_checkpoint(a.model);
  gdsr::GDSR<float> model(cfg);
  const nn::Checkpoint ck = nn::load_checkpoint<float>(a.model, model, nullptr);
  nlohmann::json meta = nlohmann::json::parse(gdsr::checkpoint_metadata(cfg));
  meta["weights_of"] = std::filesystem::path(a.model).filename().string();
  meta["trained_steps"] = ck.step;
  nn::save_checkpoint<float>(a.out, model, nullptr, ck.step, meta.dump());  // temp file, then rename
  std::printf("wrote %s: %lld parameters at step %lld (%.1f MB; %s was %.1f MB)\n", a.out.c_str(),
              static_cast<long long>(model.num_parameters()), static_cast<long long>(ck.step),
              std::filesystem::file_size(a.out) / 1e6, a.model.c_str(), std::filesystem::file_size(a.model) / 1e6);
}

}  // namespace

void add_weights_command(CLI::App& app) {
  auto a = std::make_shared<WeightsArgs>();
  CLI::App* c = app.add_subcommand("weights", "write a checkpoint's model weights alone (for shipping in models/)");
  c->add_option("--model", a->model, "checkpoint written by gdsr train")->required();
  c->add_option("--out", a->out, "weights file to write")->required();
  c->callback([a]() { run_weights(*a); });
}

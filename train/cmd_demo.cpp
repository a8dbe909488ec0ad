// gdsr demo: the autograd part of the main job (scripts/demo.sh runs it first, then the
// garment pipeline with `gdsr data make`, `gdsr train`, `gdsr infer`, `gdsr eval`):
//   1. our autograd + AdamW train a small MLP (loss falls);
//   2. gradient-check summary over every op (float64 central differences).
#include "autograd/gradcheck_suite.hpp"

#include "gdsr/error.hpp"
#include "gdsr/cli/progress_bar.hpp"
#include "train/demo_mlp.hpp"
#include "gdsr/cli/commands.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <stdexcept>

namespace {

struct DemoArgs {
  bool quick = false;  // fewer MLP steps (used by the CLI test)
};

void stage_mlp(const DemoArgs& a) {
  std::printf("== 1. MLP regression with our autograd (float32, AdamW) ==\n");
  nn::DemoMlpOptions o;
  if (a.quick) o.steps = 300;
  const nn::DemoMlpResult r = nn::train_demo_mlp(o, [](int64_t step, double loss) {
    std::printf("  step %5lld  mse %.6f\n", static_cast<long long>(step), loss);
    std::fflush(stdout);
  });
  const double drop = r.loss.empty() ? 0 : r.loss.front() / std::max(r.final_loss, 1e-30);
  std::printf("  loss %.5f -> %.6f (%.0fx lower), test mse %.6f, %.2f s\n", r.loss.empty() ? 0.0 : r.loss.front(),
              r.final_loss, drop, r.test_loss, r.seconds);
}

void stage_gradcheck() {
  std::printf("== 2. Gradient checks (float64 central differences, relative error) ==\n");
  gdsr::ProgressBar bar("gradcheck");
  const auto results = ag::run_gradcheck_suite(7, bar.callback());
  bar.finish();
  int failed = 0;
  double worst = 0;
  for (const auto& r : results) {
    std::printf("  %-44s %.2e %s\n", r.op.c_str(), r.result.max_rel_error, r.passed() ? "ok" : "FAILED");
    failed += r.passed() ? 0 : 1;
    worst = std::max(worst, r.result.max_rel_error);
  }
  std::printf("  %zu ops checked, worst %.2e, %d above tolerance 1e-6\n", results.size(), worst, failed);
  if (failed) gdsr::fail("demo", std::to_string(failed) + " gradient checks failed");
}

}  // namespace

void add_demo_command(CLI::App& app) {
  auto a = std::make_shared<DemoArgs>();
  CLI::App* c = app.add_subcommand("demo", "autograd demo: MLP training and the gradient-check summary");
  c->add_flag("--quick", a->quick, "fewer MLP steps");
  c->callback([a]() {
    stage_mlp(*a);
    stage_gradcheck();
  });
}

// A small self-contained training run for the command line's demo and for tests: fit
// f(x, y) = sin(pi x) cos(pi y) on [-1, 1]^2 with an MLPStack + Linear in float32, AdamW,
// full batch, MSE loss.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

namespace nn {

struct DemoMlpOptions {
  int64_t samples = 256;                      // training points, uniform in [-1, 1]^2
  std::vector<int64_t> widths = {2, 64, 64};  // MLP blocks (no norm), then Linear -> 1
  int64_t steps = 1500;
  double lr = 3e-3;
  double weight_decay = 0.0;
  bool amsgrad = false;
  int64_t report_every = 100;  // callback period (steps); the last step is always reported
  uint64_t seed = 1;
};

struct DemoMlpResult {
  std::vector<double> loss;  // training MSE before each step (steps values)
  double final_loss = 0;     // training MSE after the last step
  double test_loss = 0;      // MSE on a separate set of points after training
  double seconds = 0;        // wall time of the training loop
};

// progress(step, loss) is called every report_every steps (may be empty). No printing.
DemoMlpResult train_demo_mlp(const DemoMlpOptions& opt,
                             const std::function<void(int64_t step, double loss)>& progress = {});

}  // namespace nn

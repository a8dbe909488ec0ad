// Schedules: learning-rate step decay and the GDSR loss-weight ramp. Pure functions of the
// step (or epoch) count, so resuming from a checkpoint gives the same values.
#pragma once

#include <cstdint>

namespace nn {

// lr(step) = max(base * gamma^floor(step / every), floor_lr). The reference script: base
// 1e-4, gamma 0.5, every 50,000 iterations, floor 1e-6.
struct StepDecay {
  double base = 1e-4;
  double gamma = 0.5;
  int64_t every = 50000;
  double floor_lr = 1e-6;
  double operator()(int64_t step) const;
  // Sets the optimizer's learning rate for this step (any type with set_lr(double)).
  template <class Opt> void apply(Opt& opt, int64_t step) const { opt.set_lr((*this)(step)); }
};

// A weight that moves by `delta` every `every` epochs from `start` until it reaches `target`
// and then stays there: value(e) = start + delta * floor(e / every), clamped at target.
// GDSR paper: lambda_c = {1.9, -0.2, 10, 1.0}, lambda_w = {0.1, +0.2, 10, 1.0}.
struct RampSchedule {
  double start = 1.0;
  double delta = 0.0;
  int64_t every = 1;
  double target = 1.0;
  double operator()(int64_t epoch) const;
};
// (gdsr::lambda_schedule in gdsr/losses.hpp builds the two GDSR ramps from the loss config.)

}  // namespace nn

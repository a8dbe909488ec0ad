#include "nn/lr_schedule.hpp"

#include "autograd/tensor.hpp"

#include <algorithm>
#include <cmath>

namespace nn {

double StepDecay::operator()(int64_t step) const {
  if (every <= 0) throw ag::Error("nn::StepDecay: 'every' must be positive");
  if (step < 0) throw ag::Error("nn::StepDecay: negative step");
  const double lr = base * std::pow(gamma, static_cast<double>(step / every));
  return std::max(lr, floor_lr);
}

double RampSchedule::operator()(int64_t epoch) const {
  if (every <= 0) throw ag::Error("nn::RampSchedule: 'every' must be positive");
  if (epoch < 0) throw ag::Error("nn::RampSchedule: negative epoch");
  const double v = start + delta * static_cast<double>(epoch / every);
  if (delta > 0) return std::min(v, target);
  if (delta < 0) return std::max(v, target);
  return v;
}

LossWeights gdsr_loss_weights(int64_t epoch, bool enabled) {
  if (!enabled) return {1.0, 1.0};
  const RampSchedule c{1.9, -0.2, 10, 1.0}, w{0.1, 0.2, 10, 1.0};
  return {c(epoch), w(epoch)};
}

}  // namespace nn

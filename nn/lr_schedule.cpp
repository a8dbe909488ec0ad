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

}  // namespace nn

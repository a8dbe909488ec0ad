#include "train/train_state.hpp"

#include "gdsr/error.hpp"

#include <cmath>
#include <cstring>
#include <exception>

namespace gdsr {
namespace {

// Doubles travel as their IEEE bits: bit-exact and independent of JSON number printing.
uint64_t bits(double d) {
  uint64_t b;
  std::memcpy(&b, &d, sizeof d);
  return b;
}
double from_bits(uint64_t b) {
  double d;
  std::memcpy(&d, &b, sizeof d);
  return d;
}

}  // namespace

nlohmann::json progress_to_json(const TrainProgress& p) {
  nlohmann::json j;
  j["step"] = p.step;
  j["frame_pos"] = p.frame_pos;
  j["epoch"] = p.epoch;
  nlohmann::json order = nlohmann::json::array();
  for (const auto& [s, t] : p.order) order.push_back({s, t});
  j["order"] = order;
  j["order_rng"] = p.order_rng;
  j["noise"] = {p.noise.s[0], p.noise.s[1], p.noise.s[2], p.noise.s[3], p.noise.spare_bits};
  j["noise_has_spare"] = p.noise.has_spare;
  j["frames_per_step"] = p.frames_per_step;
  j["frames_per_epoch"] = p.frames_per_epoch;
  j["data"] = p.data;
  j["has_best"] = p.has_best;
  j["best_bits"] = bits(p.best);
  j["interval_sum_bits"] = bits(p.interval_sum);
  j["interval_count"] = p.interval_count;
  return j;
}

TrainProgress progress_from_json(const nlohmann::json& j, const std::string& path) {
  TrainProgress p;
  try {
    p.step = j.at("step").get<int64_t>();
    p.frame_pos = j.at("frame_pos").get<int64_t>();
    p.epoch = j.at("epoch").get<int>();
    for (const auto& e : j.at("order")) p.order.push_back({e.at(0).get<int>(), e.at(1).get<int>()});
    p.order_rng = j.at("order_rng").get<std::string>();
    const auto& n = j.at("noise");
    if (!n.is_array() || n.size() != 5) gdsr::fail(path, "training state: noise must hold 5 numbers");
    for (int i = 0; i < 4; ++i) p.noise.s[i] = n.at(static_cast<size_t>(i)).get<uint64_t>();
    p.noise.spare_bits = n.at(4).get<uint64_t>();
    p.noise.has_spare = j.at("noise_has_spare").get<bool>();
    p.frames_per_step = j.at("frames_per_step").get<int>();
    p.frames_per_epoch = j.at("frames_per_epoch").get<int64_t>();
    p.data = j.at("data").get<std::vector<std::string>>();
    p.has_best = j.at("has_best").get<bool>();
    p.best = from_bits(j.at("best_bits").get<uint64_t>());
    p.interval_sum = from_bits(j.at("interval_sum_bits").get<uint64_t>());
    p.interval_count = j.at("interval_count").get<int64_t>();
  } catch (const gdsr::Error&) {
    throw;
  } catch (const std::exception&) {
    gdsr::fail(path, "training state is incomplete or has a field of the wrong type");
  }
  if (p.step < 0 || p.frame_pos < 0 || p.frames_per_step <= 0 || p.frames_per_epoch <= 0 || p.interval_count < 0 ||
      p.epoch < -1)
    gdsr::fail(path, "training state has a negative step, position or count");
  if (p.epoch >= 0 && static_cast<int64_t>(p.order.size()) != p.frames_per_epoch)
    gdsr::fail(path, "training state: the epoch order has " + std::to_string(p.order.size()) + " frames, expected " +
                         std::to_string(p.frames_per_epoch));
  if (p.order_rng.empty()) gdsr::fail(path, "training state: no frame-order RNG state");
  if (!std::isfinite(p.best) || !std::isfinite(p.interval_sum))
    gdsr::fail(path, "training state holds a non-finite figure");
  return p;
}

}  // namespace gdsr

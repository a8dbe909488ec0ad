#include "train/loss_config.hpp"

#include "gdsr/error.hpp"
#include "gdsr/model/json_value.hpp"
#include "nn/lr_schedule.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace gdsr {

namespace {

void check_keys(const nlohmann::json& j, const std::vector<std::string>& allowed, const std::string& where) {
  if (!j.is_object()) gdsr::fail("loss config", std::string(where) + " must be an object");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end())
      gdsr::fail("loss config", "unknown key '" + it.key() + "' in " + where);
}

template <class V> void read(const nlohmann::json& j, const char* key, V& v, const std::string& where) {
  if (!j.contains(key)) return;
  try {
    v = json_value<V>(j.at(key));
  } catch (const std::exception&) {  // wrong type, or a count that is not a whole number in range
    gdsr::fail("loss config", std::string(where) + "." + key + " has the wrong type or is out of range");
  }
}

void read_term(const nlohmann::json& j, const char* key, LossTerm& t, const std::string& where) {
  if (!j.contains(key)) return;
  const std::string w = where + "." + key;
  check_keys(j.at(key), {"on", "weight"}, w);
  read(j.at(key), "on", t.on, w);
  read(j.at(key), "weight", t.weight, w);
  if (!std::isfinite(t.weight) || t.weight < 0)
    gdsr::fail("loss config", std::string(w) + ".weight must be finite and >= 0");
}

nlohmann::json term_json(const LossTerm& t) { return {{"on", t.on}, {"weight", t.weight}}; }

}  // namespace

LossConfig loss_config_from_json(const nlohmann::json& j) {
  LossConfig c;
  check_keys(j, {"coarse", "fine", "schedule"}, "loss config");
  if (j.contains("coarse")) {
    const auto& k = j.at("coarse");
    check_keys(k, {"position", "normal", "strain", "smooth", "dihedral"}, "coarse");
    read_term(k, "position", c.c_position, "coarse");
    read_term(k, "normal", c.c_normal, "coarse");
    read_term(k, "strain", c.c_strain, "coarse");
    read_term(k, "smooth", c.c_smooth, "coarse");
    read_term(k, "dihedral", c.c_dihedral, "coarse");
  }
  if (j.contains("fine")) {
    const auto& k = j.at("fine");
    check_keys(
        k,
        {"position", "normal_map", "vgg", "image_l1", "strain", "smooth", "image_background", "image_l1_garment_only"},
        "fine");
    read_term(k, "position", c.f_position, "fine");
    read_term(k, "normal_map", c.f_normal_map, "fine");
    read_term(k, "vgg", c.f_vgg, "fine");
    read_term(k, "image_l1", c.f_image_l1, "fine");
    read_term(k, "strain", c.f_strain, "fine");
    read_term(k, "smooth", c.f_smooth, "fine");
    read(k, "image_background", c.image_background, "fine");
    read(k, "image_l1_garment_only", c.image_l1_garment_only, "fine");
  }
  if (j.contains("schedule")) {
    const auto& k = j.at("schedule");
    check_keys(k, {"on", "lambda_c_start", "lambda_w_start", "step", "every_epochs", "lambda_c_end", "lambda_w_end"},
               "schedule");
    read(k, "on", c.schedule, "schedule");
    read(k, "lambda_c_start", c.lambda_c_start, "schedule");
    read(k, "lambda_w_start", c.lambda_w_start, "schedule");
    read(k, "step", c.lambda_step, "schedule");
    read(k, "every_epochs", c.lambda_every_epochs, "schedule");
    read(k, "lambda_c_end", c.lambda_c_end, "schedule");
    read(k, "lambda_w_end", c.lambda_w_end, "schedule");
    if (c.lambda_every_epochs <= 0) gdsr::fail("loss config", "schedule.every_epochs must be positive");
    if (!(c.lambda_step >= 0)) gdsr::fail("loss config", "schedule.step must be >= 0");
  }
  return c;
}

nlohmann::json loss_config_to_json(const LossConfig& c) {
  nlohmann::json j;
  j["coarse"] = {{"position", term_json(c.c_position)},
                 {"normal", term_json(c.c_normal)},
                 {"strain", term_json(c.c_strain)},
                 {"smooth", term_json(c.c_smooth)},
                 {"dihedral", term_json(c.c_dihedral)}};
  j["fine"] = {{"position", term_json(c.f_position)},
               {"normal_map", term_json(c.f_normal_map)},
               {"vgg", term_json(c.f_vgg)},
               {"image_l1", term_json(c.f_image_l1)},
               {"strain", term_json(c.f_strain)},
               {"smooth", term_json(c.f_smooth)},
               {"image_background", c.image_background},
               {"image_l1_garment_only", c.image_l1_garment_only}};
  j["schedule"] = {{"on", c.schedule},
                   {"lambda_c_start", c.lambda_c_start},
                   {"lambda_w_start", c.lambda_w_start},
                   {"step", c.lambda_step},
                   {"every_epochs", c.lambda_every_epochs},
                   {"lambda_c_end", c.lambda_c_end},
                   {"lambda_w_end", c.lambda_w_end}};
  return j;
}

LossConfig load_loss_config(const std::string& path) {
  std::ifstream in(path);
  if (!in) gdsr::fail("loss config", "cannot open " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return loss_config_from_json_text(ss.str(), path);
}

LossConfig loss_config_from_json_text(const std::string& text, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    gdsr::fail("loss config", std::string(path) + " is not valid JSON: " + e.what());
  }
  try {
    return loss_config_from_json(j);
  } catch (const std::exception& e) {  // gdsr::Error, or a JSON type error
    gdsr::fail(path, e.what());
  }
}

Lambdas lambda_schedule(const LossConfig& c, int epoch) {
  Lambdas l;
  if (!c.schedule) {
    l.coarse = c.lambda_c_end;
    l.fine = c.lambda_w_end;
    return l;
  }
  const int64_t e = std::max(0, epoch);
  const int64_t every = c.lambda_every_epochs;
  auto ramp = [&](double start, double end) {  // moves toward its end value and stops there
    return nn::RampSchedule{start, start > end ? -c.lambda_step : c.lambda_step, every, end}(e);
  };
  l.coarse = ramp(c.lambda_c_start, c.lambda_c_end);
  l.fine = ramp(c.lambda_w_start, c.lambda_w_end);
  return l;
}

}  // namespace gdsr

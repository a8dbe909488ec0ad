#include "gdsr/model/model_config.hpp"

#include "gdsr/model/features.hpp"
#include "gdsr/model/json_value.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace gdsr {

using nlohmann::json;

int64_t ModelConfig::field_params() const {
  int64_t total = 0;
  for (const FieldLayer& l : field_layers()) total += l.out * l.in + l.out;
  return total;
}

std::vector<ModelConfig::FieldLayer> ModelConfig::field_layers() const {
  std::vector<FieldLayer> layers;
  int64_t offset = 0;
  const int64_t W = field_width;
  for (int l = 0; l <= field_wire_layers; ++l) {
    FieldLayer f;
    f.in = l == 0 ? 3 : W;
    f.out = l == field_wire_layers ? 3 : W;
    f.w_begin = offset;
    f.b_begin = offset + f.in * f.out;
    offset = f.b_begin + f.out;
    layers.push_back(f);
  }
  return layers;
}

namespace {
void check_widths(const char* name, const std::vector<int64_t>& w) {
  if (w.size() < 2) gdsr::fail("model_config", std::string(name) + " needs at least two widths");
  for (int64_t v : w)
    if (v <= 0) gdsr::fail("model_config", std::string(name) + " has a non-positive width");
}
// A real-valued key must be finite and satisfy `ok`; the one-line error names the key, the
// allowed range and the value.
void require(const char* key, double value, bool ok, const char* range) {
  if (ok && std::isfinite(value)) return;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", value);
  gdsr::fail("model_config", std::string(key) + " must be " + range + ", got " + buf);
}
}  // namespace

void ModelConfig::validate() const {
  check_widths("node_encoder_pre", node_encoder_pre);
  check_widths("node_encoder_post", node_encoder_post);
  check_widths("edge_encoder", edge_encoder);
  check_widths("decoder", decoder);
  check_widths("e_widths", e_widths);
  check_widths("a_widths", a_widths);
  if (node_encoder_pre.front() != kNodeFeatures)
    gdsr::fail("model_config", "node_encoder_pre must start at " + std::to_string(kNodeFeatures) + " (node features)");
  if (node_encoder_post.front() != node_encoder_pre.back())
    gdsr::fail("model_config", "node_encoder_post must start where node_encoder_pre ends");
  if (edge_encoder.front() != kEdgeFeatures)
    gdsr::fail("model_config", "edge_encoder must start at " + std::to_string(kEdgeFeatures) + " (edge features)");
  if (edge_encoder.back() != latent()) gdsr::fail("model_config", "edge_encoder must end at the latent size");
  if (decoder.front() != latent()) gdsr::fail("model_config", "decoder must start at the latent size");
  if (z_detail <= 0 || z_detail >= decoder.back())
    gdsr::fail("model_config", "z_detail must be in (0, decoder.back())");
  if (e_widths.front() != 3 * z_disp()) gdsr::fail("model_config", "e_widths must start at 3 * z_disp");
  if (a_widths.front() != 3 * z_detail) gdsr::fail("model_config", "a_widths must start at 3 * z_detail");
  if (mp_steps < 0) gdsr::fail("model_config", "mp_steps must be >= 0");
  if (field_width <= 0) gdsr::fail("model_config", "field_width must be positive");
  if (field_wire_layers < 1) gdsr::fail("model_config", "field_wire_layers must be >= 1");
  // The domain of the maths: WIRE's Gaussian envelope needs s0 > 0 (at s0 = 0, |psi| =
  // e^{-omega0 Im x} overflows float32 at Im x = -20 for omega0 = 5).
  require("wire_s0", wire_s0, wire_s0 > 0, "> 0");
  require("wire_omega0", wire_omega0, wire_omega0 >= 0, ">= 0");
  require("sigma_b", sigma_b, sigma_b > 0, "> 0 (metres)");
  require("sigma_l", sigma_l, sigma_l > 0, "> 0 (metres)");
  require("noise_std", noise_std, noise_std >= 0, ">= 0 (metres)");
  require("node_length_unit", node_length_unit, node_length_unit > 0, "> 0 (metres)");
  require("frame_eps", frame_eps, frame_eps > 0 && frame_eps < 1, "in (0, 1) (relative to a triangle's size)");
  require("a_proj_init_gain", a_proj_init_gain, a_proj_init_gain > 0, "> 0");
  require("e_scale_init", e_scale_init, true, "finite");
  require("field_scale_init", field_scale_init, true, "finite");
}

#define GDSR_CONFIG_FIELDS(X)                                                                                  \
  X(node_encoder_pre)                                                                                          \
  X(node_encoder_post)                                                                                         \
  X(edge_encoder) X(mp_steps) X(layer_edge_mlps) X(h_norm) X(decoder) X(z_detail) X(e_widths) X(e_scale_init)  \
      X(e_carry) X(a_widths) X(a_proj_init_gain) X(field_width) X(field_wire_layers) X(wire_omega0) X(wire_s0) \
          X(field_scale_init) X(sigma_b) X(sigma_l) X(noise_std) X(node_length_unit) X(frame_eps) X(seed)

ModelConfig model_config_from_json_text(const std::string& text, const std::string& origin) {
  json j;
  try {
    j = json::parse(text);
  } catch (const std::exception& e) {
    gdsr::fail("model_config", std::string(origin) + " is not valid JSON: " + e.what());
  }
  if (!j.is_object()) gdsr::fail("model_config", std::string(origin) + " is not a JSON object");
  ModelConfig c;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    bool known = false;
    try {
#define X(name)                                  \
  if (key == #name) {                            \
    known = true;                                \
    c.name = json_value<decltype(c.name)>(it.value()); \
  }
      GDSR_CONFIG_FIELDS(X)
#undef X
    } catch (const std::exception& e) {
      gdsr::fail("model_config", std::string(origin) + ": bad value for '" + key + "': " + e.what());
    }
    if (!known && key.rfind("_", 0) != 0)  // keys starting with '_' are comments
      gdsr::fail("model_config", std::string(origin) + ": unknown key '" + key + "'");
  }
  try {
    c.validate();
  } catch (const std::exception& e) {
    throw gdsr::Error(std::string(e.what()) + " (" + origin + ")");  // re-raise with the file named
  }
  return c;
}

ModelConfig load_model_config(const std::string& path) {
  std::ifstream in(path);
  if (!in) gdsr::fail("model_config", "cannot open " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return model_config_from_json_text(ss.str(), path);
}

std::string model_config_to_json_text(const ModelConfig& c) {
  json j;
#define X(name) j[#name] = c.name;
  GDSR_CONFIG_FIELDS(X)
#undef X
  return j.dump(2) + "\n";
}

void save_model_config(const ModelConfig& c, const std::string& path) {
  write_file_atomic(path, model_config_to_json_text(c));
}

}  // namespace gdsr

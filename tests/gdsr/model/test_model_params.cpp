// Presets and parameter counts: the paper preset's count against a count derived from the
// architecture here, field size P = 17091, and config JSON round trip / errors.
#include <doctest/doctest.h>

#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_config.hpp"

#include <cstdio>
#include <string>

using namespace gdsr;

namespace {
const std::string kConfigs = std::string(GDSR_SOURCE_DIR) + "/configs/";

// Reference MLP block: Linear(i,o) + Linear(o,o), both with bias; optional scale/shift 2o.
int64_t block(int64_t i, int64_t o, bool scale_shift = false) {
  return i * o + o + o * o + o + (scale_shift ? 2 * o : 0);
}
int64_t stack(std::vector<int64_t> w) {
  int64_t n = 0;
  for (size_t k = 0; k + 1 < w.size(); ++k) n += block(w[k], w[k + 1]);
  return n;
}

// The error message of parsing `text` as a config ("" if it is accepted).
std::string msg(const std::string& text) {
  try {
    model_config_from_json_text(text, "test");
  } catch (const std::runtime_error& e) {
    return std::string(e.what());
  }
  return std::string();
}
}  // namespace

TEST_CASE("model params: paper preset parameter count and field size") {
  const ModelConfig cfg = load_model_config(kConfigs + "paper.json");
  // Field: (3*64 + 64) + 4 * (64*64 + 64) + (64*3 + 3).
  CHECK(cfg.field_params() == 17091);
  const int64_t P = 17091;

  // H: node encoder 23-32-16-8, Linear 8->8, 8-16-32-64-128; ring-1 and layer edge encoders
  // 9-512-256-128; 6 steps of ring-1 / ring-2 / layer edge blocks (384 -> 128) and a node
  // block (512 -> 128, scale/shift); decoder 128-256-512-640.
  const int64_t H = stack({23, 32, 16, 8}) + (8 * 8 + 8) + stack({8, 16, 32, 64, 128}) + 2 * stack({9, 512, 256, 128}) +
                    6 * (3 * block(384, 128) + block(512, 128, true)) + stack({128, 256, 512, 640});
  // E: 384-128-256-128-64, Linear 64 -> 9, per-axis scale and bias.
  const int64_t E = stack({384, 128, 256, 128, 64}) + (64 * 9 + 9) + 3 + 3;
  // A: 1536-1024-512-256, two bias-free 256 -> P, per-axis output scale.
  const int64_t A = stack({1536, 1024, 512, 256}) + 2 * 256 * P + 3;

  GDSR<float> model(cfg);
  const int64_t counted = model.num_parameters();
  MESSAGE("paper preset: " << counted << " parameters (H " << model.h().num_parameters() << ", E "
                           << model.e().num_parameters() << ", A " << model.a().num_parameters() << "), "
                           << counted * 4.0 / 1e6 << " MB in float32; field P = " << P);
  CHECK(model.h().num_parameters() == H);
  CHECK(model.e().num_parameters() == E);
  CHECK(model.a().num_parameters() == A);
  CHECK(counted == H + E + A);
  // The reference's "about 65 MB in float32".
  CHECK(counted * 4.0 / 1e6 > 60);
  CHECK(counted * 4.0 / 1e6 < 70);
}

TEST_CASE("model params: presets load, validate and round-trip through JSON") {
  for (const char* name : {"paper", "small", "tiny"}) {
    const ModelConfig c = load_model_config(kConfigs + name + ".json");
    const ModelConfig d = model_config_from_json_text(model_config_to_json_text(c));
    CHECK(model_config_to_json_text(c) == model_config_to_json_text(d));
    GDSR<float> m(c);
    MESSAGE(name << ": " << m.num_parameters() << " parameters, field P = " << c.field_params());
  }
  const std::string tmp = std::string(GDSR_BINARY_DIR) + "/test_model_config.json";
  ModelConfig c = load_model_config(kConfigs + "small.json");
  c.seed = 42;
  save_model_config(c, tmp);
  CHECK(load_model_config(tmp).seed == 42);
  std::remove(tmp.c_str());
}

TEST_CASE("model params: bad configs throw clear errors") {
  CHECK(msg(R"({"mp_stepz": 3})").find("unknown key 'mp_stepz'") != std::string::npos);
  CHECK(msg(R"({"mp_steps": "six"})").find("bad value for 'mp_steps'") != std::string::npos);
  CHECK(msg(R"({"edge_encoder": [9, 64, 32]})").find("edge_encoder") != std::string::npos);
  CHECK(msg(R"({"node_encoder_pre": [20, 8]})").find("23") != std::string::npos);
  CHECK(msg(R"({"sigma_b": -1})").find("sigma_b") != std::string::npos);
  CHECK(msg("{not json").find("not valid JSON") != std::string::npos);
  CHECK(msg(R"({"_comment": "ok", "mp_steps": 2})").empty());
  CHECK_THROWS_AS(load_model_config(kConfigs + "does_not_exist.json"), std::runtime_error);
}

TEST_CASE("model params: values outside the domain of the maths are refused naming the key") {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"({"wire_s0": 0})", "wire_s0"},         {R"({"wire_s0": -2})", "wire_s0"},
      {R"({"wire_omega0": -1})", "wire_omega0"}, {R"({"frame_eps": 0})", "frame_eps"},
      {R"({"frame_eps": -1e-6})", "frame_eps"},  {R"({"frame_eps": 1.5})", "frame_eps"},
      {R"({"sigma_l": 0})", "sigma_l"},          {R"({"noise_std": -0.1})", "noise_std"},
      {R"({"field_width": -4})", "field_width"}, {R"({"e_widths": [1536, -128, 64]})", "e_widths"},
      {R"({"node_length_unit": 0})", "node_length_unit"},
  };
  for (const auto& [text, key] : bad) {
    CAPTURE(text);
    const std::string m = msg(text);
    CHECK(m.find(key) != std::string::npos);
    CHECK(m.find('\n') == std::string::npos);  // one line
  }
  CHECK(msg(R"({"wire_s0": 0})").find("got 0") != std::string::npos);
  CHECK(msg(R"({"wire_s0": 0.5, "frame_eps": 1e-6})").empty());
}

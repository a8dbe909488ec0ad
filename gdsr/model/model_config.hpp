// Sizes and constants of the GDSR network (H, E, A and the WIRE field). Every size is a
// field; presets live in configs/*.json (paper, small, tiny). Lengths in metres.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace gdsr {

struct ModelConfig {
  // ---- Mesh-Graph-Net H (all blocks are the reference "MLP block") ----
  // Node encoder: MLP blocks through node_encoder_pre (first = 23 node features), then
  // Linear(last, last) + per-channel norm, then MLP blocks through node_encoder_post
  // (first = last of pre, last = latent).
  std::vector<int64_t> node_encoder_pre{23, 32, 16, 8};
  std::vector<int64_t> node_encoder_post{8, 16, 32, 64, 128};
  std::vector<int64_t> edge_encoder{9, 512, 256, 128};  // ring-1 and layer edges (9 features)
  int mp_steps = 6;                                     // message-passing steps
  bool layer_edge_mlps = true;                          // build the layer-edge encoder and per-step MLPs
  bool h_norm = true;                                   // per-channel graph norm inside the H blocks
  std::vector<int64_t> decoder{128, 256, 512, 640};     // last = z_detail + z_disp
  int64_t z_detail = 512;                               // first z_detail channels -> A

  // ---- Correction decoder E ----
  std::vector<int64_t> e_widths{384, 128, 256, 128, 64};  // MLP blocks, first = 3 * z_disp
  double e_scale_init = 0.1;                              // per-axis scale = init * randn(3)
  // Carry: C^ = C + D + gamma d_{t-1}, with d_{t-1} = C^_{t-1} - C_{t-1} the previous
  // correction (world) and gamma a learned scalar from 0. E's displacements live in each
  // triangle's frame, the history in world axes: "keep the previous correction" is a product
  // of inputs, which the MLPs did not learn (false: the reference, D alone). Measured on the
  // small preset (models/README.md): teacher-forced, gamma rises to 0.45 and the one-step error
  // falls to 0.66x of upsampling, but a roll-out, which has no true history, gets worse.
  bool e_carry = false;

  // ---- Hyper-net A and the WIRE field ----
  std::vector<int64_t> a_widths{1536, 1024, 512, 256};  // MLP blocks, first = 3 * z_detail
  double a_proj_init_gain = 1.0;                        // multiplies the default init of the two 256 -> P maps
  int64_t field_width = 64;                             // hidden width of the per-triangle field
  int field_wire_layers = 5;                            // layers followed by WIRE (first real, rest complex)
  double wire_omega0 = 5.0;
  double wire_s0 = 10.0;
  double field_scale_init = 0.01;  // per-axis output scale = init * randn(3)

  // ---- features ----
  double sigma_b = 0.015;    // body interaction distance, m
  double sigma_l = 0.020;    // layer-edge distance, m
  double noise_std = 0.003;  // training noise on the history features, m
  // Metres per unit of the node features that are lengths (velocity, acceleration, body
  // interaction, previous correction and corrected velocity); 1 is the reference's metres.
  // Those features are millimetres to centimetres next to unit normals, and the node encoder
  // mixes them all in its first layer. At 1 the small model shipped for revision 13 data ignored
  // its history (its output moved 0.01 mm for a 4 mm change of the previous correction);
  // trained at 0.01, 0.3 mm (models/README.md).
  double node_length_unit = 1.0;
  double frame_eps = 1e-2;   // local-frame normalisation eps, relative to each triangle's size (frames.hpp)

  uint64_t seed = 1;  // parameter initialisation

  // Derived sizes.
  int64_t latent() const { return node_encoder_post.back(); }
  int64_t z_disp() const { return decoder.back() - z_detail; }
  // Complex parameters per triangle: (3W + W) + (n-1)(W^2 + W) + (3W + 3).
  int64_t field_params() const;
  // Column offsets of layer l (0-based, 0..field_wire_layers) inside the P parameters:
  // weight [out x in] row-major at [w_begin, w_begin + out*in), bias right after.
  struct FieldLayer {
    int64_t in, out, w_begin, b_begin;
  };
  std::vector<FieldLayer> field_layers() const;

  // Throws gdsr::Error naming the inconsistent field.
  void validate() const;
};

// JSON <-> config. Unknown keys, wrong types or inconsistent sizes throw (one line, naming
// the file and key). Missing keys keep the defaults above (the paper preset).
ModelConfig model_config_from_json_text(const std::string& text, const std::string& origin = "json");
ModelConfig load_model_config(const std::string& path);
std::string model_config_to_json_text(const ModelConfig& c);
void save_model_config(const ModelConfig& c, const std::string& path);  // temp + rename

}  // namespace gdsr

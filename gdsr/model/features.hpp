// Graph features of one frame (reference-facts "Graph features"): 23 values per LR vertex,
// 9 per directed ring-1 edge, 9 per directed layer edge (multi-layer garments only).
// Positions in metres; velocities are per-frame differences (not divided by dt).
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/model/graph.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "gdsr/model/model_config.hpp"

#include "nn/rng.hpp"

namespace gdsr {

// Widths of the feature rows (the network's input widths).
constexpr int kNodeFeatures = 23;  // per LR vertex
constexpr int kEdgeFeatures = 9;   // per edge (ring-1, ring-2, layer)

// Nearest body surface point b and its outward unit normal n_b per garment vertex
// (V x 3 each, metres).
struct BodyContact {
  Points3 point;
  Points3 normal;
};

// Everything one frame t needs (LR vertex positions, V x 3, metres).
struct FrameInput {
  Points3 C_t, C_tm1, C_tm2;   // LR simulation at t, t-1, t-2
  Points3 Chat_tm1, Chat_tm2;  // corrected LR at t-1, t-2 (downsampled GT in training,
                               // the model's own outputs in a roll-out)
  // Body at t queried at C_t and at C_{t-1}; has_body = false: no body, zero interaction.
  bool has_body = false;
  BodyContact contact_t, contact_tm1;
};

template <class T> struct GraphFeatures {
  ag::Tensor<T> node;   // V x 23: n_t, v_t, a_t, m_t, p_t, m_tm1, p_tm1, d_tm1, vhat_tm1
  ag::Tensor<T> ring1;  // E1 x 9 (graph.ring1 order): x_j-x_i, |.| at t; at t-1; rest length
  ag::Tensor<T> layer;  // EL x 9, rest length replaced by sigma_l; undefined when EL = 0
  LayerEdges layer_edges;
};

// The corrected history C^_{t-1}, C^_{t-2} as tensors (V x 3 each, metres), for training
// through a roll-out (`gdsr train --unroll`): the history features d_tm1 and vhat_tm1 are then
// differentiable in them. Their values must be FrameInput's Chat_tm1 and Chat_tm2.
template <class T> struct HistoryTensors { ag::Tensor<T> Chat_tm1, Chat_tm2; };

// C_t: the positions at t as a tensor (may require grad; values must equal in.C_t).
// Normals, velocity, acceleration, body magnitude/vector at t and the ring-1 edge
// features at t are differentiable in C_t (body point and normal held fixed). noise:
// when non-null and cfg.noise_std > 0, Gaussian noise of std noise_std (metres) is added
// to the history features d_tm1 and vhat_tm1 (training only). history: when non-null, those
// features are differentiable in its tensors (same values, same noise draws).
template <class T> GraphFeatures<T> compute_features(const GarmentGraph& g, const ag::Tensor<T>& C_t,
                                                     const FrameInput& in, const ModelConfig& cfg,
                                                     nn::Rng* noise = nullptr,
                                                     const HistoryTensors<T>* history = nullptr);

// Layer-edge features only (EL x 9) for given directed pairs.
template <class T>
ag::Tensor<T> layer_edge_features(const LayerEdges& le, const ag::Tensor<T>& C_t, const Points3& C_tm1, double sigma_l);

}  // namespace gdsr

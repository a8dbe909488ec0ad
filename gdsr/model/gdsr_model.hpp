// The GDSR network (paper 3-4.4): features -> Mesh-Graph-Net H -> z = [z_detail | z_disp];
// correction decoder E: C_hat = C + D; hyper-net A + WIRE field per needed LR triangle:
// G = barycentric upsample of C_hat + residual in the triangle's local frame of C_hat.
// Positions in metres. Templated on the scalar (float: training/inference, double:
// gradient checks).
//
// Usage (inference, one frame):
//   gdsr::GDSR<float> model(gdsr::load_model_config("configs/paper.json"));
//   gdsr::GarmentGraph graph = gdsr::build_graph(lr_garment);
//   gdsr::HrRequest all = gdsr::hr_request_all(correspondence);
//   ag::NoGradGuard ng;
//   auto out = model.forward(graph, frame_input, &all);
//   Points3 C_hat = gdsr::to_points(out.C_hat), G = gdsr::to_points(out.G);
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/model/features.hpp"
#include "gdsr/model/graph.hpp"
#include "gdsr/model/model_a.hpp"
#include "gdsr/model/model_config.hpp"
#include "gdsr/model/model_e.hpp"
#include "gdsr/model/model_h.hpp"
#include "nn/module.hpp"

#include <memory>
#include <vector>

namespace gdsr {

// HR samples to predict: LR triangle and barycentric weights (of F(tri,0..2)) per sample.
struct HrRequest {
  std::vector<int> tri;
  Bary bary;  // N x 3
  int size() const { return static_cast<int>(tri.size()); }
};
// Every HR vertex, in HR vertex order (inference).
HrRequest hr_request_all(const Correspondence& c);
// The given HR vertices, in the given order (training patches).
HrRequest hr_request_subset(const Correspondence& c, const std::vector<int>& hr_vertices);

// Wall-clock seconds spent building the forward pass of each block (optional profiling).
struct GdsrTimings {
  double features = 0, h = 0, e = 0, a = 0, field = 0;
};

// Parts of a trained model switched off at inference (the ablations of issue #12, without
// retraining): correction off gives C_hat = C (D = 0), detail off gives G = the barycentric
// upsample of C_hat (A is not run, residual 0).
struct GdsrAblation {
  bool correction = true;
  bool detail = true;
};

template <class T> struct GdsrOutput {
  GraphFeatures<T> features;
  ag::Tensor<T> C;       // V x 3, the LR input positions used at t
  ag::Tensor<T> z;       // V x (z_detail + z_disp)
  ag::Tensor<T> D;       // V x 3 correction displacements (world)
  ag::Tensor<T> C_hat;   // V x 3 corrected LR positions = C + D
  ag::Index faces;       // LR triangles A was evaluated on (ascending)
  ag::Index group;       // per HR sample: row of its triangle in `faces`
  FieldParams<T> field;  // [faces x P] complex field parameters (re, im)
  // Per requested HR sample (undefined without a request):
  ag::Tensor<T> upsampled;       // N x 3 barycentric sample of C_hat
  ag::Tensor<T> residual_local;  // N x 3 residual in the local frame of C_hat's triangle
  ag::Tensor<T> residual;        // N x 3 residual in world
  ag::Tensor<T> G;               // N x 3 HR positions = upsampled + residual
};

template <class T> class GDSR : public nn::Module<T> {
 public:
  explicit GDSR(const ModelConfig& cfg);

  // hr null: only C_hat (A is not run). noise non-null: training noise on the history
  // features (ModelConfig::noise_std). history non-null: the output is differentiable in the
  // corrected history too (training through a roll-out; features.hpp).
  GdsrOutput<T> forward(const GarmentGraph& g, const FrameInput& in, const HrRequest* hr, nn::Rng* noise = nullptr,
                        GdsrTimings* timings = nullptr, const HistoryTensors<T>* history = nullptr) const;
  // Same with the positions at t given as a tensor (values must equal in.C_t), e.g. a leaf
  // requiring grad to differentiate with respect to C.
  GdsrOutput<T> forward(const GarmentGraph& g, const ag::Tensor<T>& C_t, const FrameInput& in, const HrRequest* hr,
                        nn::Rng* noise = nullptr, GdsrTimings* timings = nullptr,
                        const HistoryTensors<T>* history = nullptr) const;
  // E and A (and the composition) for a given latent z [V x (z_detail + z_disp)]; d_prev
  // [V x 3]: the previous correction C^_{t-1} - C_{t-1}, used by the carry (ModelConfig::e_carry).
  GdsrOutput<T> decode(const GarmentGraph& g, const ag::Tensor<T>& C_t, const ag::Tensor<T>& z, const HrRequest* hr,
                       GdsrTimings* timings = nullptr, const ag::Tensor<T>* d_prev = nullptr) const;

  ag::Tensor<T> carry;  // [1 x 1] gamma, only with ModelConfig::e_carry

  void set_ablation(const GdsrAblation& a) { ablation_ = a; }
  const GdsrAblation& ablation() const { return ablation_; }
  const ModelConfig& config() const { return cfg_; }
  MeshGraphNet<T>& h() const { return *h_; }
  CorrectionDecoder<T>& e() const { return *e_; }
  HyperNet<T>& a() const { return *a_; }

 private:
  ModelConfig cfg_;
  GdsrAblation ablation_;
  std::shared_ptr<MeshGraphNet<T>> h_;
  std::shared_ptr<CorrectionDecoder<T>> e_;
  std::shared_ptr<HyperNet<T>> a_;
};

}  // namespace gdsr

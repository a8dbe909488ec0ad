// Training losses of GDSR (paper 4.5, weights of the reference code).
//
// Coarse, on the corrected LR garment C^ [V x 3] (metres) vs the downsampled ground truth C*:
//   w_pos L1(C^, C*) + w_nrm L1(N(C^), N(C*)) + w_str strain + w_smo smoothness(C^)
//   + w_dih L1(theta(C^), theta(C*)),  defaults 1, 0.01, 0.01, 100, 0.003.
//   strain = L1(|F_u|) + L1(|F_v|) + L1(F^_u . F^_v) against the ground truth's (each a mean
//   over faces). L1 = mean absolute difference over all elements.
// Fine, over a PatchBatch of P patches (the reference's batching):
//   w_pos L1(inside positions of all patches) + w_nm [w_vgg VGG(images) + w_l1 L1(images)]
//   + w_str (sum_p strain_p) / P + w_smo (sum_p smoothness_p) / P,
//   defaults 1, 0.01 (1, 1), 0.01, 0.05. Images: [P x 3 x S x S] normal maps (patches.hpp).
//   smoothness_p is over the patch's inside vertices (exact rings with halo on).
// Total: lambda_c coarse + lambda_w fine, with the schedule of the paper: lambda_c from
// 1.9 down and lambda_w from 0.1 up by 0.2 every 10 epochs, clamped at 1 (off: both 1).
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/geometry_ad.hpp"
#include "gdsr/mesh.hpp"
#include "gdsr/patches.hpp"

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace gdsr {

struct LossTerm {
  bool on = true;
  double weight = 1.0;
};

struct LossConfig {
  // coarse
  LossTerm c_position{true, 1.0};
  LossTerm c_normal{true, 0.01};
  LossTerm c_strain{true, 0.01};
  LossTerm c_smooth{true, 100.0};
  LossTerm c_dihedral{true, 0.003};
  // fine
  LossTerm f_position{true, 1.0};
  LossTerm f_normal_map{true, 0.01};  // weight of [VGG + L1] on the normal maps
  LossTerm f_vgg{true, 1.0};          // inside the normal-map term
  LossTerm f_image_l1{true, 1.0};     // inside the normal-map term
  LossTerm f_strain{true, 0.01};
  LossTerm f_smooth{true, 0.05};
  double image_background = 0.0;      // colour of background pixels (both images)
  bool image_l1_garment_only = false; // false: L1 over whole images (reference); true: garment pixels
  // lambda schedule
  bool schedule = true;
  double lambda_c_start = 1.9, lambda_w_start = 0.1, lambda_step = 0.2;
  int lambda_every_epochs = 10;
  double lambda_c_end = 1.0, lambda_w_end = 1.0;
};

// JSON: {"coarse": {"position": {"on": true, "weight": 1}, "normal": .., "strain": ..,
// "smooth": .., "dihedral": ..}, "fine": {"position", "normal_map", "vgg", "image_l1",
// "strain", "smooth", "image_background", "image_l1_garment_only"}, "schedule": {"on",
// "lambda_c_start", "lambda_w_start", "step", "every_epochs", "lambda_c_end",
// "lambda_w_end"}}. Missing keys keep their defaults; unknown keys throw.
LossConfig loss_config_from_json(const nlohmann::json& j);
nlohmann::json loss_config_to_json(const LossConfig& c);
LossConfig load_loss_config(const std::string& path);  // throws naming the file

struct Lambdas {
  double coarse = 1, fine = 1;
};
Lambdas lambda_schedule(const LossConfig& c, int epoch);  // epoch counts from 0

template <class T> struct CoarseLoss {
  ag::Tensor<T> total;  // [1 x 1], weighted sum of the active terms
  // Unweighted term values (0 when off), for logging.
  double position = 0, normal = 0, strain = 0, smooth = 0, dihedral = 0;
  std::map<std::string, double> log() const;
};

template <class T> struct FineLoss {
  ag::Tensor<T> total;  // [1 x 1]
  double position = 0, vgg = 0, image_l1 = 0, strain = 0, smooth = 0;  // unweighted; strain/smooth are means over patches
  int patches = 0;
  std::map<std::string, double> log() const;
};

// lr: topology of the LR garment (with UV). C_hat [V x 3]; C_star: V x 3 ground truth.
template <class T>
CoarseLoss<T> coarse_loss(const LossConfig& cfg, const MeshTopology& lr, const ag::Tensor<T>& C_hat,
                          const Points3& C_star);

// Feature loss between two image batches [P x 3 x S x S] (colours in 0..1) -> [1 x 1]; the
// VGG cosine loss of nn/ in training. Empty function: the VGG term is skipped.
template <class T>
using ImageLossFn = std::function<ag::Tensor<T>(const ag::Tensor<T>& pred, const ag::Tensor<T>& target)>;

// G_pred [batch.vertices.size() x 3]: the model's HR positions for batch.vertices (same
// order). G_star: the full HR ground truth frame (HR vertices x 3).
template <class T>
FineLoss<T> fine_loss(const LossConfig& cfg, const PatchBatch& batch, const ag::Tensor<T>& G_pred,
                      const Points3& G_star, const ImageLossFn<T>& image_loss = {});

// lambda_c coarse.total + lambda_w fine.total (either may be undefined = absent).
template <class T>
ag::Tensor<T> total_loss(const Lambdas& l, const ag::Tensor<T>& coarse, const ag::Tensor<T>& fine);

}  // namespace gdsr

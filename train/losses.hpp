// Training losses of GDSR (paper 4.5, weights of the reference code).
//
// Coarse, on the corrected LR garment C^ [V x 3] (metres) vs the downsampled ground truth C*:
//   w_pos L1(C^, C*) + w_nrm L1(N(C^), N(C*)) + w_str strain + w_smo smoothness(C^)
//   + w_dih L1(theta(C^), theta(C*)),  defaults 1, 0.01, 0.01, 100, 0.003.
//   strain = L1(|F_u|) + L1(|F_v|) + L1(F^_u . F^_v) against the ground truth's (each a mean
//   over faces; shear with the floor kShearEps, geometry_ad.hpp). L1 = mean absolute
//   difference over all elements, except that the dihedral term weights each pair by the
//   weight of dihedral_terms (exactly 1 on faces with at least 1% of their rest area, fading
//   with the area below: a predicted sliver's angle gradient 1 / height would dominate).
// Fine, over a PatchBatch of P patches (the reference's batching):
//   w_pos L1(inside positions of all patches) + w_nm [w_vgg VGG(images) + w_l1 L1(images)]
//   + w_str (sum_p strain_p) / P + w_smo (sum_p smoothness_p) / P,
//   defaults 1, 0.01 (1, 1), 0.01, 0.05. Images: [P x 3 x S x S] normal maps (patches.hpp).
//   smoothness_p is over the patch's inside vertices (exact rings with halo on).
// Total: lambda_c coarse + lambda_w fine (lambda schedule and term switches: loss_config.hpp).
#pragma once

#include "autograd/tensor.hpp"
#include "train/loss_config.hpp"
#include "gdsr/geometry/geometry_ad.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "train/patches.hpp"

#include <functional>
#include <map>
#include <string>

namespace gdsr {

template <class T> struct CoarseLoss {
  ag::Tensor<T> total;  // [1 x 1], weighted sum of the active terms
  // Unweighted term values (0 when off), for logging.
  double position = 0, normal = 0, strain = 0, smooth = 0, dihedral = 0;
  std::map<std::string, double> log() const;
};

template <class T> struct FineLoss {
  ag::Tensor<T> total;  // [1 x 1]
  double position = 0, vgg = 0, image_l1 = 0, strain = 0,
         smooth = 0;  // unweighted; strain/smooth are means over patches
  int patches = 0;
  std::map<std::string, double> log() const;
};

// lr: topology of the LR garment (with UV). C_hat [V x 3]; C_star: V x 3 ground truth.
template <class T> CoarseLoss<T> coarse_loss(const LossConfig& cfg, const MeshTopology& lr, const ag::Tensor<T>& C_hat,
                                             const Points3& C_star);

// Feature loss between two image batches [P x 3 x S x S] (colours in 0..1) -> [1 x 1]; the
// VGG cosine loss of nn/ in training. Empty function: the VGG term is skipped.
template <class T> using ImageLossFn =
    std::function<ag::Tensor<T>(const ag::Tensor<T>& pred, const ag::Tensor<T>& target)>;

// G_pred [batch.vertices.size() x 3]: the model's HR positions for batch.vertices (same
// order). G_star: the full HR ground truth frame (HR vertices x 3).
template <class T> FineLoss<T> fine_loss(const LossConfig& cfg, const PatchBatch& batch, const ag::Tensor<T>& G_pred,
                                         const Points3& G_star, const ImageLossFn<T>& image_loss = {});

// lambda_c coarse.total + lambda_w fine.total (either may be undefined = absent).
template <class T> ag::Tensor<T> total_loss(const Lambdas& l, const ag::Tensor<T>& coarse, const ag::Tensor<T>& fine);

}  // namespace gdsr

#include "train/losses.hpp"

#include "gdsr/error.hpp"

#include "autograd/ops_elementwise.hpp"
#include "autograd/ops_index.hpp"
#include "autograd/ops_loss.hpp"
#include "autograd/ops_reduce.hpp"
#include "autograd/ops_shape.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace gdsr {

// ---- loss terms ------------------------------------------------------------------------------

namespace {

template <class T> void accumulate(ag::Tensor<T>& total, const ag::Tensor<T>& term, double w) {
  const ag::Tensor<T> t = ag::mul_scalar(term, static_cast<T>(w));
  total = total.defined() ? ag::add(total, t) : t;
}

template <class T> ag::Tensor<T> finish(ag::Tensor<T> total) {
  return total.defined() ? total : ag::Tensor<T>::scalar(T(0));
}

// L1 of the three strain measures, each a mean over faces: 3 x the mean over all entries.
template <class T> ag::Tensor<T> strain_l1(const ag::Tensor<T>& X, const ag::Tensor<T>& Xgt, const MeshTopology& t) {
  ag::Tensor<T> gt;
  {
    ag::NoGradGuard ng;
    gt = strain_measures(Xgt, t);
  }
  return ag::mul_scalar(ag::l1_loss(strain_measures(X, t), gt), T(3));
}

template <class T> ag::Tensor<T> no_grad(const std::function<ag::Tensor<T>()>& f) {
  ag::NoGradGuard ng;
  return f();
}

template <class T> ag::Tensor<T> gather_points(const Points3& P, const std::vector<int>& rows) {
  ag::Tensor<T> t = ag::Tensor<T>::zeros({static_cast<int64_t>(rows.size()), 3});
  T* d = t.data();
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i] < 0 || rows[i] >= P.rows()) gdsr::fail("losses", "ground-truth row out of range");
    for (int k = 0; k < 3; ++k) d[3 * i + k] = static_cast<T>(P(rows[i], k));
  }
  return t;
}

}  // namespace

template <class T> std::map<std::string, double> CoarseLoss<T>::log() const {
  return {{"c_position", position}, {"c_normal", normal},     {"c_strain", strain},
          {"c_smooth", smooth},     {"c_dihedral", dihedral}, {"coarse", total.defined() ? double(total.item()) : 0.0}};
}

template <class T> std::map<std::string, double> FineLoss<T>::log() const {
  return {{"f_position", position}, {"f_vgg", vgg},       {"f_image_l1", image_l1},
          {"f_strain", strain},     {"f_smooth", smooth}, {"fine", total.defined() ? double(total.item()) : 0.0}};
}

template <class T> CoarseLoss<T> coarse_loss(const LossConfig& cfg, const MeshTopology& lr, const ag::Tensor<T>& C_hat,
                                             const Points3& C_star) {
  if (C_star.rows() != lr.num_vertices)
    gdsr::fail("losses", "coarse ground truth has " + std::to_string(C_star.rows()) + " rows, mesh has " +
                             std::to_string(lr.num_vertices));
  const ag::Tensor<T> gt = to_tensor<T>(C_star);
  CoarseLoss<T> out;
  ag::Tensor<T> total;
  if (cfg.c_position.on) {
    const ag::Tensor<T> l = ag::l1_loss(C_hat, gt);
    out.position = static_cast<double>(l.item());
    accumulate(total, l, cfg.c_position.weight);
  }
  if (cfg.c_normal.on) {
    const ag::Tensor<T> ngt = no_grad<T>([&] { return vertex_normals(gt, lr); });
    const ag::Tensor<T> l = ag::l1_loss(vertex_normals(C_hat, lr), ngt);
    out.normal = static_cast<double>(l.item());
    accumulate(total, l, cfg.c_normal.weight);
  }
  if (cfg.c_strain.on && !lr.strain_faces.empty()) {
    const ag::Tensor<T> l = strain_l1(C_hat, gt, lr);
    out.strain = static_cast<double>(l.item());
    accumulate(total, l, cfg.c_strain.weight);
  }
  if (cfg.c_smooth.on) {
    const ag::Tensor<T> l = smoothness(C_hat, lr);
    out.smooth = static_cast<double>(l.item());
    accumulate(total, l, cfg.c_smooth.weight);
  }
  if (cfg.c_dihedral.on && !lr.pair_f0.empty()) {
    const ag::Tensor<T> agt = no_grad<T>([&] { return dihedral_angles(gt, lr); });
    // |angle - gt| weighted by the prediction's fade weight: 1 on healthy pairs (the plain L1),
    // and a bounded gradient on predicted slivers (see dihedral_terms).
    const DihedralTerms<T> d = dihedral_terms(C_hat, lr);
    const ag::Tensor<T> l = ag::mean(ag::mul(d.weight, ag::abs(ag::sub(d.angle, agt))));
    out.dihedral = static_cast<double>(l.item());
    accumulate(total, l, cfg.c_dihedral.weight);
  }
  out.total = finish(total);
  return out;
}

template <class T> FineLoss<T> fine_loss(const LossConfig& cfg, const PatchBatch& batch, const ag::Tensor<T>& G_pred,
                                         const Points3& G_star, const ImageLossFn<T>& image_loss) {
  const int P = static_cast<int>(batch.patches.size());
  if (P == 0) gdsr::fail("losses", "fine loss on an empty patch batch");
  if (G_pred.dim() != 2 || G_pred.cols() != 3 || G_pred.rows() != static_cast<int64_t>(batch.vertices.size()))
    gdsr::fail("losses", "fine prediction must be [" + std::to_string(batch.vertices.size()) + " x 3], got " +
                             ag::shape_str(G_pred.shape()));
  const ag::Tensor<T> gt_batch = gather_points<T>(G_star, batch.vertices);

  const bool want_images = cfg.f_normal_map.on && ((cfg.f_vgg.on && image_loss) || cfg.f_image_l1.on);
  const bool full_images =
      cfg.f_normal_map.on && ((cfg.f_vgg.on && image_loss) || (cfg.f_image_l1.on && !cfg.image_l1_garment_only));
  std::vector<ag::Tensor<T>> pos, pos_gt, img, img_gt, pix, pix_gt;
  ag::Tensor<T> strain_sum, smooth_sum;
  FineLoss<T> out;
  out.patches = P;
  for (int p = 0; p < P; ++p) {
    const Patch& patch = batch.patches[p];
    const ag::Tensor<T> X = ag::index_select_rows(G_pred, batch.rows[p]);
    const ag::Tensor<T> Xg = no_grad<T>([&] { return ag::index_select_rows(gt_batch, batch.rows[p]); });
    if (cfg.f_position.on) {
      pos.push_back(ag::index_select_rows(X, patch.inside_rows));
      pos_gt.push_back(no_grad<T>([&] { return ag::index_select_rows(Xg, patch.inside_rows); }));
    }
    if (want_images) {
      const ag::Tensor<T> n = vertex_normals(X, patch.topo);
      const ag::Tensor<T> ng = no_grad<T>([&] { return vertex_normals(Xg, patch.topo); });
      const int64_t len = 3 * static_cast<int64_t>(patch.size) * patch.size;
      if (full_images) {
        img.push_back(ag::reshape(draw_normal_map(n, patch, cfg.image_background), {1, len}));
        img_gt.push_back(no_grad<T>([&] {
          return ag::reshape(draw_normal_map(ng, patch, cfg.image_background), {1, len});
        }));
      }
      if (cfg.f_image_l1.on && cfg.image_l1_garment_only) {
        pix.push_back(normal_map_pixels(n, patch));
        pix_gt.push_back(no_grad<T>([&] { return normal_map_pixels(ng, patch); }));
      }
    }
    if (cfg.f_strain.on && !patch.topo.strain_faces.empty()) {
      const ag::Tensor<T> l = strain_l1(X, Xg, patch.topo);
      strain_sum = strain_sum.defined() ? ag::add(strain_sum, l) : l;
    }
    if (cfg.f_smooth.on) {
      const ag::Tensor<T> l = smoothness(X, patch.topo, &patch.inside_rows);
      smooth_sum = smooth_sum.defined() ? ag::add(smooth_sum, l) : l;
    }
  }

  ag::Tensor<T> total;
  if (cfg.f_position.on) {
    const ag::Tensor<T> l = ag::l1_loss(ag::concat_rows(pos), no_grad<T>([&] { return ag::concat_rows(pos_gt); }));
    out.position = static_cast<double>(l.item());
    accumulate(total, l, cfg.f_position.weight);
  }
  if (want_images) {
    ag::Tensor<T> nm;
    const int64_t S = batch.patches[0].size;
    for (const Patch& p : batch.patches)
      if (p.size != S) gdsr::fail("losses", "patches of different sizes in one batch");
    ag::Tensor<T> I, Ig;
    if (full_images) {
      I = ag::concat_rows(img);
      Ig = no_grad<T>([&] { return ag::concat_rows(img_gt); });
    }
    if (cfg.f_vgg.on && image_loss) {
      const ag::Tensor<T> l = image_loss(ag::reshape(I, {P, 3, S, S}), ag::reshape(Ig, {P, 3, S, S}));
      out.vgg = static_cast<double>(l.item());
      accumulate(nm, l, cfg.f_vgg.weight);
    }
    if (cfg.f_image_l1.on) {
      const ag::Tensor<T> l =
          cfg.image_l1_garment_only
              ? ag::l1_loss(ag::concat_rows(pix), no_grad<T>([&] { return ag::concat_rows(pix_gt); }))
              : ag::l1_loss(I, Ig);
      out.image_l1 = static_cast<double>(l.item());
      accumulate(nm, l, cfg.f_image_l1.weight);
    }
    if (nm.defined()) accumulate(total, nm, cfg.f_normal_map.weight);
  }
  if (strain_sum.defined()) {
    const ag::Tensor<T> l = ag::mul_scalar(strain_sum, static_cast<T>(1.0 / P));
    out.strain = static_cast<double>(l.item());
    accumulate(total, l, cfg.f_strain.weight);
  }
  if (smooth_sum.defined()) {
    const ag::Tensor<T> l = ag::mul_scalar(smooth_sum, static_cast<T>(1.0 / P));
    out.smooth = static_cast<double>(l.item());
    accumulate(total, l, cfg.f_smooth.weight);
  }
  out.total = finish(total);
  return out;
}

template <class T> ag::Tensor<T> total_loss(const Lambdas& l, const ag::Tensor<T>& coarse, const ag::Tensor<T>& fine) {
  ag::Tensor<T> total;
  if (coarse.defined()) accumulate(total, coarse, l.coarse);
  if (fine.defined()) accumulate(total, fine, l.fine);
  return finish(total);
}

#define GDSR_LOSSES_INSTANTIATE(T)                                                                                     \
  template struct CoarseLoss<T>;                                                                                       \
  template struct FineLoss<T>;                                                                                         \
  template CoarseLoss<T> coarse_loss<T>(const LossConfig&, const MeshTopology&, const ag::Tensor<T>&, const Points3&); \
  template FineLoss<T> fine_loss<T>(const LossConfig&, const PatchBatch&, const ag::Tensor<T>&, const Points3&,        \
                                    const ImageLossFn<T>&);                                                            \
  template ag::Tensor<T> total_loss<T>(const Lambdas&, const ag::Tensor<T>&, const ag::Tensor<T>&);

GDSR_LOSSES_INSTANTIATE(float)
GDSR_LOSSES_INSTANTIATE(double)

}  // namespace gdsr

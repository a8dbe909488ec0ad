#include "gdsr/losses.hpp"

#include "nn/lr_schedule.hpp"

#include "autograd/ops_elementwise.hpp"
#include "autograd/ops_index.hpp"
#include "autograd/ops_loss.hpp"
#include "autograd/ops_shape.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace gdsr {

// ---- configuration --------------------------------------------------------------------------

namespace {

[[noreturn]] void cfg_fail(const std::string& msg) { throw std::runtime_error("loss config: " + msg); }

void check_keys(const nlohmann::json& j, const std::vector<std::string>& allowed, const std::string& where) {
  if (!j.is_object()) cfg_fail(where + " must be an object");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end())
      cfg_fail("unknown key '" + it.key() + "' in " + where);
}

template <class V> void read(const nlohmann::json& j, const char* key, V& v, const std::string& where) {
  if (!j.contains(key)) return;
  try {
    v = j.at(key).get<V>();
  } catch (const nlohmann::json::exception&) {
    cfg_fail(where + "." + key + " has the wrong type");
  }
}

void read_term(const nlohmann::json& j, const char* key, LossTerm& t, const std::string& where) {
  if (!j.contains(key)) return;
  const std::string w = where + "." + key;
  check_keys(j.at(key), {"on", "weight"}, w);
  read(j.at(key), "on", t.on, w);
  read(j.at(key), "weight", t.weight, w);
  if (!std::isfinite(t.weight) || t.weight < 0) cfg_fail(w + ".weight must be finite and >= 0");
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
    check_keys(k, {"position", "normal_map", "vgg", "image_l1", "strain", "smooth", "image_background",
                   "image_l1_garment_only"},
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
    if (c.lambda_every_epochs <= 0) cfg_fail("schedule.every_epochs must be positive");
    if (!(c.lambda_step >= 0)) cfg_fail("schedule.step must be >= 0");
  }
  return c;
}

nlohmann::json loss_config_to_json(const LossConfig& c) {
  nlohmann::json j;
  j["coarse"] = {{"position", term_json(c.c_position)}, {"normal", term_json(c.c_normal)},
                 {"strain", term_json(c.c_strain)},     {"smooth", term_json(c.c_smooth)},
                 {"dihedral", term_json(c.c_dihedral)}};
  j["fine"] = {{"position", term_json(c.f_position)}, {"normal_map", term_json(c.f_normal_map)},
               {"vgg", term_json(c.f_vgg)},           {"image_l1", term_json(c.f_image_l1)},
               {"strain", term_json(c.f_strain)},     {"smooth", term_json(c.f_smooth)},
               {"image_background", c.image_background}, {"image_l1_garment_only", c.image_l1_garment_only}};
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
  if (!in) throw std::runtime_error("loss config: cannot open " + path);
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("loss config: " + path + " is not valid JSON: " + e.what());
  }
  try {
    return loss_config_from_json(j);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
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
    if (rows[i] < 0 || rows[i] >= P.rows()) throw ag::Error("losses: ground-truth row out of range");
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

template <class T>
CoarseLoss<T> coarse_loss(const LossConfig& cfg, const MeshTopology& lr, const ag::Tensor<T>& C_hat,
                          const Points3& C_star) {
  if (C_star.rows() != lr.num_vertices)
    throw ag::Error("losses: coarse ground truth has " + std::to_string(C_star.rows()) + " rows, mesh has " +
                    std::to_string(lr.num_vertices));
  const ag::Tensor<T> gt = points_tensor<T>(C_star);
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
    const ag::Tensor<T> l = ag::l1_loss(dihedral_angles(C_hat, lr), agt);
    out.dihedral = static_cast<double>(l.item());
    accumulate(total, l, cfg.c_dihedral.weight);
  }
  out.total = finish(total);
  return out;
}

template <class T>
FineLoss<T> fine_loss(const LossConfig& cfg, const PatchBatch& batch, const ag::Tensor<T>& G_pred,
                      const Points3& G_star, const ImageLossFn<T>& image_loss) {
  const int P = static_cast<int>(batch.patches.size());
  if (P == 0) throw ag::Error("losses: fine loss on an empty patch batch");
  if (G_pred.dim() != 2 || G_pred.cols() != 3 || G_pred.rows() != static_cast<int64_t>(batch.vertices.size()))
    throw ag::Error("losses: fine prediction must be [" + std::to_string(batch.vertices.size()) + " x 3], got " +
                    ag::shape_str(G_pred.shape()));
  const ag::Tensor<T> gt_batch = gather_points<T>(G_star, batch.vertices);

  const bool want_images = cfg.f_normal_map.on && ((cfg.f_vgg.on && image_loss) || cfg.f_image_l1.on);
  const bool full_images = cfg.f_normal_map.on && ((cfg.f_vgg.on && image_loss) ||
                                                   (cfg.f_image_l1.on && !cfg.image_l1_garment_only));
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
        img_gt.push_back(no_grad<T>(
            [&] { return ag::reshape(draw_normal_map(ng, patch, cfg.image_background), {1, len}); }));
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
      if (p.size != S) throw ag::Error("losses: patches of different sizes in one batch");
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
      const ag::Tensor<T> l = cfg.image_l1_garment_only
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

template <class T>
ag::Tensor<T> total_loss(const Lambdas& l, const ag::Tensor<T>& coarse, const ag::Tensor<T>& fine) {
  ag::Tensor<T> total;
  if (coarse.defined()) accumulate(total, coarse, l.coarse);
  if (fine.defined()) accumulate(total, fine, l.fine);
  return finish(total);
}

#define GDSR_LOSSES_INSTANTIATE(T)                                                                             \
  template struct CoarseLoss<T>;                                                                               \
  template struct FineLoss<T>;                                                                                 \
  template CoarseLoss<T> coarse_loss<T>(const LossConfig&, const MeshTopology&, const ag::Tensor<T>&,          \
                                        const Points3&);                                                       \
  template FineLoss<T> fine_loss<T>(const LossConfig&, const PatchBatch&, const ag::Tensor<T>&, const Points3&, \
                                    const ImageLossFn<T>&);                                                    \
  template ag::Tensor<T> total_loss<T>(const Lambdas&, const ag::Tensor<T>&, const ag::Tensor<T>&);

GDSR_LOSSES_INSTANTIATE(float)
GDSR_LOSSES_INSTANTIATE(double)

}  // namespace gdsr

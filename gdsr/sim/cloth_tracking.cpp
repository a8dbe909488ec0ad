#include "gdsr/sim/cloth_tracking.hpp"

#include "gdsr/error.hpp"

namespace sim {

using gdsr::Points3;

GuideTracker::GuideTracker(const gdsr::Correspondence& c) : corr_(c) {
  gdsr::validate_correspondence(corr_);
  weight_.assign(static_cast<size_t>(corr_.lr_vertices), 0.0);
  const gdsr::BaryMap& m = corr_.hr_from_lr;
  for (int i = 0; i < m.size(); ++i)
    for (int k = 0; k < 3; ++k) weight_[corr_.lr_F(m.tri[i], k)] += m.bary(i, k);
}

Points3 GuideTracker::lr_residual(const Points3& guide, const Points3& y) const {
  if (guide.rows() != corr_.lr_vertices || y.rows() != corr_.hr_vertices)
    gdsr::fail("sim/cloth_tracking", "got " + std::to_string(guide.rows()) + " LR and " + std::to_string(y.rows()) +
                                         " HR rows, expected " + std::to_string(corr_.lr_vertices) + " and " +
                                         std::to_string(corr_.hr_vertices));
  const Points3 target = gdsr::upsample(corr_, guide);
  const gdsr::BaryMap& m = corr_.hr_from_lr;
  Points3 r = Points3::Zero(corr_.lr_vertices, 3);
  for (int i = 0; i < m.size(); ++i)
    for (int k = 0; k < 3; ++k) r.row(corr_.lr_F(m.tri[i], k)) += m.bary(i, k) * (target.row(i) - y.row(i));
  for (int j = 0; j < corr_.lr_vertices; ++j)
    if (weight_[j] > 0) r.row(j) /= weight_[j];  // W_j = 0: no HR vertex uses j, so U never reads r_j
  return r;
}

void GuideTracker::pull(const Points3& guide_x, const Points3& guide_v, double beta, const std::vector<double>& winv,
                        Points3& x, Points3& v) const {
  if (static_cast<int>(winv.size()) != corr_.hr_vertices || v.rows() != x.rows())
    gdsr::fail("sim/cloth_tracking", "inverse masses or velocities do not match the HR vertex count");
  const Points3 dx = gdsr::upsample(corr_, lr_residual(guide_x, x));
  const Points3 dv = gdsr::upsample(corr_, lr_residual(guide_v, v));
  for (int i = 0; i < corr_.hr_vertices; ++i) {
    if (winv[i] == 0) continue;
    x.row(i) += beta * dx.row(i);
    v.row(i) += beta * dv.row(i);
  }
}

std::vector<double> untangled_pull_weights(const std::vector<double>& winv, const std::vector<char>& tangled,
                                           const gdsr::Faces& F, int rings) {
  if (tangled.size() != winv.size() || (F.size() > 0 && F.maxCoeff() >= static_cast<int>(winv.size())))
    gdsr::fail("sim/cloth_tracking", "tangled flags or faces do not match the vertex count");
  std::vector<char> near = tangled;
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<char> grown = near;
    for (int f = 0; f < F.rows(); ++f)
      if (near[F(f, 0)] || near[F(f, 1)] || near[F(f, 2)]) grown[F(f, 0)] = grown[F(f, 1)] = grown[F(f, 2)] = 1;
    near.swap(grown);
  }
  std::vector<double> w = winv;
  for (size_t i = 0; i < w.size(); ++i)
    if (near[i]) w[i] = 0;
  return w;
}

}  // namespace sim

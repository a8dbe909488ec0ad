#include "infer/evaluate.hpp"

#include "gdsr/error.hpp"

#include "autograd/tensor.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/geometry_ad.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

#include <stdexcept>

namespace gdsr {

cv::Mat uv_normal_map(const UVRaster& raster, const Faces& F, const Points3& V) {
  const Points3 N = vertex_normals(V, F);
  cv::Mat img(raster.height, raster.width, CV_32FC3, cv::Scalar(0, 0, 0));
#pragma omp parallel for
  for (int j = 0; j < raster.height; ++j) {
    auto* row = img.ptr<cv::Vec3f>(j);
    for (int i = 0; i < raster.width; ++i) {
      const size_t p = static_cast<size_t>(j) * raster.width + i;
      const int f = raster.tri[p];
      if (f < 0) continue;
      Vec3 n = Vec3::Zero();
      for (int k = 0; k < 3; ++k) n += static_cast<double>(raster.bary[3 * p + k]) * N.row(F(f, k)).transpose();
      for (int c = 0; c < 3; ++c) row[i][c] = static_cast<float>(0.5 * n[c] + 0.5);
    }
  }
  return img;
}

cv::Mat garment_mask(const UVRaster& raster) {
  cv::Mat mask(raster.height, raster.width, CV_8U, cv::Scalar(0));
  for (int j = 0; j < raster.height; ++j)
    for (int i = 0; i < raster.width; ++i)
      if (raster.tri[static_cast<size_t>(j) * raster.width + i] >= 0) mask.at<uint8_t>(j, i) = 255;
  return mask;
}

namespace {

void add_scaled(StrainEnergies& sum, const StrainEnergies& e, double w) {
  sum.E_u += w * e.E_u;
  sum.E_v += w * e.E_v;
  sum.E_uv += w * e.E_uv;
}

}  // namespace

Evaluation evaluate(const Dataset& d, const std::vector<Points3>& G, int first_frame, int ssim_every,
                    const ProgressFn& progress) {
  const int T = static_cast<int>(d.hr_frames.size());
  if (first_frame < 0 || first_frame + static_cast<int>(G.size()) > T)
    gdsr::fail("evaluate", "predicted frames " + std::to_string(first_frame) + ".." +
                               std::to_string(first_frame + static_cast<int>(G.size()) - 1) +
                               " are outside the dataset's " + std::to_string(T) + " frames");
  if (ssim_every < 1) ssim_every = 1;
  Evaluation ev;
  int n_ssim = 0;
  const cv::Mat mask = garment_mask(d.raster);
  const int count = static_cast<int>(G.size());
  for (int k = 0; k < count; ++k) {
    const int t = first_frame + k;
    const Points3& truth = d.hr_frames[t];
    if (G[k].rows() != truth.rows())
      gdsr::fail("evaluate", "frame " + std::to_string(t) + " has " + std::to_string(G[k].rows()) +
                                 " HR vertices, the dataset " + std::to_string(truth.rows()));
    const Points3 up = upsample(d.corr, d.lr_frames[t]);
    const Points3 scale = at_lr_scale(d.corr, truth);
    FrameEvaluation f;
    f.frame = t;
    f.error = (G[k] - truth).rowwise().norm().mean();
    f.error_lr = (up - truth).rowwise().norm().mean();
    f.error_scale = (scale - truth).rowwise().norm().mean();
    if (k % ssim_every == 0) {
      const cv::Mat ref = uv_normal_map(d.raster, d.hr.F, truth);
      f.has_ssim = true;
      const SsimScore g = ssim_score(uv_normal_map(d.raster, d.hr.F, G[k]), ref, mask);
      const SsimScore lr = ssim_score(uv_normal_map(d.raster, d.hr.F, up), ref, mask);
      const SsimScore sc = ssim_score(uv_normal_map(d.raster, d.hr.F, scale), ref, mask);
      f.ssim = g.whole, f.ssim_garment = g.garment;
      f.ssim_lr = lr.whole, f.ssim_garment_lr = lr.garment;
      f.ssim_scale = sc.whole, f.ssim_garment_scale = sc.garment;
      ev.mean.ssim += f.ssim;
      ev.mean.ssim_lr += f.ssim_lr;
      ev.mean.ssim_scale += f.ssim_scale;
      ev.mean.ssim_garment += f.ssim_garment;
      ev.mean.ssim_garment_lr += f.ssim_garment_lr;
      ev.mean.ssim_garment_scale += f.ssim_garment_scale;
      ++n_ssim;
    }
    f.energies = strain_energies(d.hr, G[k]);
    f.energies_lr = strain_energies(d.hr, up);
    f.energies_hr = strain_energies(d.hr, truth);
    ev.mean.error += f.error / count;
    ev.mean.error_lr += f.error_lr / count;
    ev.mean.error_scale += f.error_scale / count;
    add_scaled(ev.mean.energies, f.energies, 1.0 / count);
    add_scaled(ev.mean.energies_lr, f.energies_lr, 1.0 / count);
    add_scaled(ev.mean.energies_hr, f.energies_hr, 1.0 / count);
    ev.frames.push_back(f);
    if (progress) progress(k + 1, count);
  }
  if (n_ssim > 0) {
    ev.mean.ssim /= n_ssim;
    ev.mean.ssim_lr /= n_ssim;
    ev.mean.ssim_scale /= n_ssim;
    ev.mean.ssim_garment /= n_ssim;
    ev.mean.ssim_garment_lr /= n_ssim;
    ev.mean.ssim_garment_scale /= n_ssim;
  }
  ev.mean.frame = -1;
  ev.truth = ev.mean.energies_hr;
  return ev;
}

}  // namespace gdsr

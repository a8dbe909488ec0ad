#include "infer/evaluate.hpp"

#include "gdsr/error.hpp"

#include "autograd/tensor.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/geometry_ad.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

#include <opencv2/quality/qualityssim.hpp>

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

double ssim(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) gdsr::fail("ssim", "images differ in size or type");
  // OpenCV's SSIM constants C1 = (0.01 * 255)^2, C2 = (0.03 * 255)^2 assume 0..255 pixels.
  cv::Mat a255, b255;
  a.convertTo(a255, CV_32F, 255.0);
  b.convertTo(b255, CV_32F, 255.0);
  const cv::Scalar s = cv::quality::QualitySSIM::compute(a255, b255, cv::noArray());
  return (s[0] + s[1] + s[2]) / 3.0;
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
      f.ssim = ssim(uv_normal_map(d.raster, d.hr.F, G[k]), ref);
      f.ssim_lr = ssim(uv_normal_map(d.raster, d.hr.F, up), ref);
      f.ssim_scale = ssim(uv_normal_map(d.raster, d.hr.F, scale), ref);
      ev.mean.ssim += f.ssim;
      ev.mean.ssim_lr += f.ssim_lr;
      ev.mean.ssim_scale += f.ssim_scale;
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
  }
  ev.mean.frame = -1;
  ev.truth = ev.mean.energies_hr;
  return ev;
}

}  // namespace gdsr

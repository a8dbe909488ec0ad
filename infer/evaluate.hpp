// Evaluation of predicted HR sequences against the HR simulation (paper 5, appendices B-C):
// vertex error, SSIM of UV normal maps, and the stretch / shear energies of appendix B.
// Two references beside the prediction: the LR simulation upsampled (the baseline GDSR must
// beat) and the HR simulation at the LR scale, downsampled and upsampled again (what a
// perfect correction E with no detail A would score: the part of the error E can remove).
#pragma once

#include "gdsr/io/progress.hpp"
#include "gdsr/data/dataset.hpp"
#include "gdsr/geometry/strain.hpp"
#include "gdsr/io/ssim.hpp"

#include <opencv2/core.hpp>

#include <vector>

namespace gdsr {

// UV normal map of an HR frame: each raster pixel coloured 0.5 n + 0.5 with n the
// barycentric interpolation of the area-weighted vertex normals of its triangle (not
// renormalised, as in training); background black. CV_32FC3 in 0..1, RGB = xyz.
cv::Mat uv_normal_map(const UVRaster& raster, const Faces& F, const Points3& V);

// The pixels a garment triangle covers: CV_8U, 255 on the garment, 0 on the layout's background
// (the mask of ssim_score's garment figure).
cv::Mat garment_mask(const UVRaster& raster);

struct FrameEvaluation {
  int frame = 0;
  double error = 0;            // mean |G - G*| over HR vertices, metres
  double error_lr = 0;         // the same for the LR simulation upsampled (baseline)
  bool has_ssim = false;       // SSIM computed on this frame (every ssim_every-th)
  double ssim = 0;             // normal maps of G vs G*, whole image (ssim_score)
  double ssim_lr = 0;          // normal maps of the upsampled LR vs G*
  double error_scale = 0;      // mean |S - G*|, S = at_lr_scale(G*) (perfect E, no A)
  double ssim_scale = 0;       // normal maps of S vs G*
  double ssim_garment = 0;     // the three SSIMs above over the garment's pixels only (ssim_score)
  double ssim_garment_lr = 0;
  double ssim_garment_scale = 0;
  StrainEnergies energies;     // of G
  StrainEnergies energies_lr;  // of the upsampled LR (baseline)
  StrainEnergies energies_hr;  // of the ground truth G*
};

struct Evaluation {
  std::vector<FrameEvaluation> frames;
  FrameEvaluation mean;  // averages (frame = -1); mean.energies_hr == truth
  StrainEnergies truth;  // of the ground truth, averaged over the same frames
};

// G: predicted HR frames for frames first_frame, first_frame + 1, ... of d.
// ssim_every: compute SSIM on every k-th frame (normal maps of 1024^2 pixels cost ~0.1 s).
Evaluation evaluate(const Dataset& d, const std::vector<Points3>& G, int first_frame, int ssim_every = 1,
                    const ProgressFn& progress = {});

}  // namespace gdsr

#include "train/detail_target.hpp"

#include "gdsr/error.hpp"
#include "gdsr/model/frames.hpp"

#include <string>

namespace gdsr {

Points3 detail_target(const Correspondence& c, const Points3& hr, const Points3& coarse_truth, const Points3& C_hat,
                      const std::vector<int>& vertices, double frame_eps) {
  if (hr.rows() != c.hr_vertices || coarse_truth.rows() != c.lr_vertices || C_hat.rows() != c.lr_vertices)
    gdsr::fail("detail_target", "expected " + std::to_string(c.hr_vertices) + " HR and " +
                                    std::to_string(c.lr_vertices) + " LR rows, got " + std::to_string(hr.rows()) +
                                    ", " + std::to_string(coarse_truth.rows()) + ", " + std::to_string(C_hat.rows()));
  ag::NoGradGuard no_grad;
  ag::Index faces;
  for (int v : vertices) {
    if (v < 0 || v >= c.hr_vertices) gdsr::fail("detail_target", "HR vertex " + std::to_string(v) + " out of range");
    faces.push_back(c.hr_from_lr.tri[static_cast<size_t>(v)]);
  }
  const auto frames = [&](const Points3& X) {  // [faces x 9]: rows x, y, z of each frame
    return triangle_frames_ad<double>(to_tensor<double>(X), c.lr_F, faces, frame_eps);
  };
  const ag::Tensor<double> Rp = frames(C_hat), Rt = frames(coarse_truth);
  Points3 out = hr;
  for (size_t k = 0; k < vertices.size(); ++k) {
    const int v = vertices[k];
    const int f = c.hr_from_lr.tri[static_cast<size_t>(v)];
    Vec3 up_truth = Vec3::Zero(), up_pred = Vec3::Zero();
    for (int j = 0; j < 3; ++j) {
      const double b = c.hr_from_lr.bary(v, j);
      up_truth += b * coarse_truth.row(c.lr_F(f, j)).transpose();
      up_pred += b * C_hat.row(c.lr_F(f, j)).transpose();
    }
    // Rows (x, y, z) of each frame: local = R d, world = R^T local.
    using Mat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    const Mat3 Rt_f = Eigen::Map<const Mat3>(Rt.data() + 9 * k), Rp_f = Eigen::Map<const Mat3>(Rp.data() + 9 * k);
    const Vec3 local = Rt_f * (hr.row(v).transpose() - up_truth);
    out.row(v) = (up_pred + Rp_f.transpose() * local).transpose();
  }
  return out;
}

}  // namespace gdsr

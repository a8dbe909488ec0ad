#include "gdsr/io/render.hpp"

#include "gdsr/error.hpp"

#include "gdsr/body/body_query.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace gdsr {

cv::Mat render_meshes(const std::vector<TriMesh>& meshes, const std::vector<cv::Vec3b>& colours,
                      const RenderOptions& opt) {
  if (meshes.empty()) gdsr::fail("render_meshes", "no meshes");
  if (opt.width <= 0 || opt.height <= 0) gdsr::fail("render_meshes", "image size must be positive");
  // One merged mesh; face_owner maps faces back to meshes.
  TriMesh all;
  std::vector<int> face_owner;
  Eigen::Index nv = 0, nf = 0;
  for (const auto& m : meshes) nv += m.V.rows(), nf += m.F.rows();
  all.V.resize(nv, 3);
  all.F.resize(nf, 3);
  face_owner.reserve(nf);
  nv = nf = 0;
  for (size_t k = 0; k < meshes.size(); ++k) {
    const TriMesh& m = meshes[k];
    if (m.V.rows() == 0 || m.F.rows() == 0) gdsr::fail("render_meshes", "mesh " + std::to_string(k) + " is empty");
    all.V.middleRows(nv, m.V.rows()) = m.V;
    all.F.middleRows(nf, m.F.rows()) = m.F.array() + static_cast<int>(nv);
    face_owner.insert(face_owner.end(), m.F.rows(), static_cast<int>(k));
    nv += m.V.rows(), nf += m.F.rows();
  }
  if (!all.V.allFinite()) gdsr::fail("render_meshes", "non-finite vertex");
  const BodyQuery scene(all);

  // Camera frame.
  const Vec3 fwd = opt.view_dir.normalized();
  Vec3 right = fwd.cross(opt.up);
  if (right.norm() < 1e-9) gdsr::fail("render_meshes", "view_dir parallel to up");
  right.normalize();
  const Vec3 up = right.cross(fwd);
  const Vec3 lo = all.V.colwise().minCoeff(), hi = all.V.colwise().maxCoeff();
  Vec3 centre = 0.5 * (lo + hi);
  const double aspect = static_cast<double>(opt.width) / opt.height;
  double half_h;  // half height of the view at the centre plane
  if (opt.ortho_half_height > 0) {
    half_h = opt.ortho_half_height;
    centre = opt.center;
  } else {
    double ex = 0, ey = 0;
    for (int c = 0; c < 8; ++c) {
      const Vec3 p((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
      ex = std::max(ex, std::abs((p - centre).dot(right)));
      ey = std::max(ey, std::abs((p - centre).dot(up)));
    }
    half_h = std::max(ey, ex / aspect) * (1 + opt.margin);
    if (!(half_h > 0)) half_h = 1;
  }
  const double radius = 0.5 * (hi - lo).norm();
  const double tan_half = std::tan(0.5 * opt.fov_deg * M_PI / 180.0);
  const double dist = opt.perspective ? half_h / tan_half + radius : 0;  // eye distance from centre
  const double far_off = radius + 1.0;                                   // ortho ray start

  const int W = opt.width, H = opt.height;
  Points3 O(static_cast<Eigen::Index>(W) * H, 3), D(static_cast<Eigen::Index>(W) * H, 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double sx = ((x + 0.5) / W * 2 - 1) * half_h * aspect, sy = (1 - (y + 0.5) / H * 2) * half_h;
      const Eigen::Index i = static_cast<Eigen::Index>(y) * W + x;
      if (opt.perspective) {
        const Vec3 eye = centre - fwd * dist;
        const Vec3 target = centre + right * sx + up * sy;
        O.row(i) = eye.transpose();
        D.row(i) = (target - eye).normalized().transpose();
      } else {
        O.row(i) = (centre + right * sx + up * sy - fwd * far_off).transpose();
        D.row(i) = fwd.transpose();
      }
    }
  const RayHits hits = scene.intersect(O, D);

  static const cv::Vec3b palette[] = {{200, 170, 150}, {80, 120, 220}, {90, 180, 90}, {60, 160, 230}, {170, 90, 170}};
  const Vec3 light = (-fwd + 0.5 * up - 0.3 * right).normalized();  // headlight from above left
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(opt.background[0], opt.background[1], opt.background[2]));
  const Points3& fn = scene.face_normals();
  const Points3& vn = scene.vertex_normals();
#pragma omp parallel for schedule(static)
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const Eigen::Index i = static_cast<Eigen::Index>(y) * W + x;
      const int f = hits.face[i];
      if (f < 0) continue;
      Vec3 n;
      if (opt.smooth) {
        const double u = hits.uv(i, 0), v = hits.uv(i, 1);
        n = (1 - u - v) * Vec3(vn.row(all.F(f, 0))) + u * Vec3(vn.row(all.F(f, 1))) + v * Vec3(vn.row(all.F(f, 2)));
        if (n.norm() < 1e-12) n = fn.row(f);
        n.normalize();
      } else {
        n = fn.row(f);
      }
      const Vec3 d = D.row(i);
      if (n.dot(d) > 0) n = -n;  // two-sided
      const double shade = std::min(1.0, opt.ambient + (1 - opt.ambient) * std::max(0.0, n.dot(light)));
      const int owner = face_owner[f];
      const cv::Vec3b col = owner < static_cast<int>(colours.size()) ? colours[owner] : palette[owner % 5];
      img.at<cv::Vec3b>(y, x) =
          cv::Vec3b(cv::saturate_cast<uchar>(col[0] * shade), cv::saturate_cast<uchar>(col[1] * shade),
                    cv::saturate_cast<uchar>(col[2] * shade));
    }
  return img;
}

cv::Mat side_by_side(const std::vector<cv::Mat>& images, const std::vector<std::string>& labels) {
  if (images.empty()) gdsr::fail("side_by_side", "no images");
  int H = 0;
  for (const auto& im : images) {
    if (im.empty() || im.type() != CV_8UC3) gdsr::fail("side_by_side", "images must be non-empty CV_8UC3");
    H = std::max(H, im.rows);
  }
  const int bar = labels.empty() ? 0 : 28;
  std::vector<cv::Mat> cols;
  for (size_t k = 0; k < images.size(); ++k) {
    cv::Mat im = images[k];
    if (im.rows != H) cv::resize(im, im, cv::Size(im.cols * H / im.rows, H));
    cv::Mat col(H + bar, im.cols, CV_8UC3, cv::Scalar(255, 255, 255));
    im.copyTo(col(cv::Rect(0, bar, im.cols, H)));
    if (k < labels.size())
      cv::putText(col, labels[k], cv::Point(6, 20), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    cols.push_back(col);
  }
  cv::Mat out;
  cv::hconcat(cols, out);
  return out;
}

void write_png_atomic(const std::string& path, const cv::Mat& image) {
  if (image.empty()) gdsr::fail("write_png_atomic", std::string(path) + ": empty image");
  const std::string tmp = path + ".tmp.png";
  bool ok = false;
  try {
    ok = cv::imwrite(tmp, image);
  } catch (const cv::Exception& e) {
    ok = false;
  }
  if (!ok) {
    std::remove(tmp.c_str());
    gdsr::fail("write_png_atomic", "cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    gdsr::fail("write_png_atomic", "cannot rename " + tmp + " to " + path);
  }
}

}  // namespace gdsr

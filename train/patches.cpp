#include "train/patches.hpp"

#include "gdsr/error.hpp"

#include "autograd/ops_elementwise.hpp"
#include "autograd/ops_index.hpp"
#include "autograd/ops_matmul.hpp"
#include "autograd/ops_shape.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/io/ssim.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace gdsr {

namespace {}  // namespace

PatchSampler::PatchSampler(UVRaster raster, GarmentMesh hr, std::vector<int> hr_vertex_lr_triangle, PatchConfig cfg,
                           double normal_eps)
    : raster_(std::move(raster)), hr_(std::move(hr)), lr_tri_(std::move(hr_vertex_lr_triangle)), cfg_(cfg) {
  const int W = raster_.width, H = raster_.height, S = cfg_.size;
  if (S <= 0 || cfg_.count <= 0) gdsr::fail("patches", "patch size and count must be positive");
  if (W < S || H < S)
    gdsr::fail("patches", "raster " + std::to_string(W) + " x " + std::to_string(H) + " smaller than a patch of " +
                              std::to_string(S));
  if (static_cast<int64_t>(raster_.tri.size()) != static_cast<int64_t>(W) * H ||
      raster_.bary.size() != raster_.tri.size() * 3)
    gdsr::fail("patches", "raster arrays do not match its size");
  if (static_cast<int>(lr_tri_.size()) != hr_.V.rows())
    gdsr::fail("patches", "hr_vertex_lr_triangle has " + std::to_string(lr_tri_.size()) + " entries for " +
                              std::to_string(hr_.V.rows()) + " HR vertices");
  const int nf = static_cast<int>(hr_.F.rows());
  integral_.assign(static_cast<size_t>(W + 1) * (H + 1), 0);
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      const int t = raster_.tri[static_cast<size_t>(j) * W + i];
      if (t >= nf) gdsr::fail("patches", "raster triangle " + std::to_string(t) + " out of range");
      const int g = t >= 0 ? 1 : 0;
      if (g) garment_pixels_.push_back(j * W + i);
      integral_[static_cast<size_t>(j + 1) * (W + 1) + i + 1] =
          g + integral_[static_cast<size_t>(j) * (W + 1) + i + 1] +
          integral_[static_cast<size_t>(j + 1) * (W + 1) + i] - integral_[static_cast<size_t>(j) * (W + 1) + i];
    }
  if (garment_pixels_.empty()) gdsr::fail("patches", "raster has no garment pixel");

  const Csr vf = vertex_faces(hr_.F, static_cast<int>(hr_.V.rows()));
  vf_offsets_ = vf.offsets;
  vf_items_ = vf.items;
  normal_eps_ = normal_eps > 0 ? normal_eps : make_topology(hr_, -1).normal_eps;

  // Fixed grid over the garment's pixel bounding box (windows clamped into the raster).
  int bx0 = W, by0 = H, bx1 = 0, by1 = 0;
  for (int p : garment_pixels_) {
    bx0 = std::min(bx0, p % W);
    bx1 = std::max(bx1, p % W + 1);
    by0 = std::min(by0, p / W);
    by1 = std::max(by1, p / W + 1);
  }
  for (int y = by0; y < by1; y += S)
    for (int x = bx0; x < bx1; x += S) {
      const int x0 = std::min(x, W - S), y0 = std::min(y, H - S);
      if (coverage(x0, y0) >= cfg_.min_coverage) grid_.push_back({x0, y0});
    }
  if (!cfg_.random_position && grid_.empty()) gdsr::fail("patches", "no grid window reaches the minimum coverage");
}

double PatchSampler::coverage(int x0, int y0) const {
  const int W = raster_.width, S = cfg_.size;
  auto I = [&](int x, int y) { return integral_[static_cast<size_t>(y) * (W + 1) + x]; };
  const int n = I(x0 + S, y0 + S) - I(x0, y0 + S) - I(x0 + S, y0) + I(x0, y0);
  return static_cast<double>(n) / (static_cast<double>(S) * S);
}

Patch PatchSampler::make_patch(int x0, int y0) const {
  const int W = raster_.width, H = raster_.height, S = cfg_.size;
  if (x0 < 0 || y0 < 0 || x0 + S > W || y0 + S > H)
    gdsr::fail("patches", "window at (" + std::to_string(x0) + ", " + std::to_string(y0) + ") leaves the raster");
  const int nv = static_cast<int>(hr_.V.rows());
  Patch p;
  p.x0 = x0;
  p.y0 = y0;
  p.size = S;

  // Faces under the pixels and their corners (the inside vertices).
  std::vector<int> pix_faces;
  for (int r = 0; r < S; ++r)
    for (int c = 0; c < S; ++c) {
      const int t = raster_.tri[static_cast<size_t>(y0 + r) * W + x0 + c];
      if (t >= 0) pix_faces.push_back(t);
    }
  std::sort(pix_faces.begin(), pix_faces.end());
  pix_faces.erase(std::unique(pix_faces.begin(), pix_faces.end()), pix_faces.end());
  std::vector<int> inside;
  for (int f : pix_faces)
    for (int k = 0; k < 3; ++k) inside.push_back(hr_.F(f, k));
  std::sort(inside.begin(), inside.end());
  inside.erase(std::unique(inside.begin(), inside.end()), inside.end());

  std::vector<int> faces = pix_faces;
  if (cfg_.halo) {
    for (int v : inside)
      for (int k = vf_offsets_[v]; k < vf_offsets_[v + 1]; ++k) faces.push_back(vf_items_[k]);
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  }

  std::vector<int> local(static_cast<size_t>(nv), -1);
  for (int v : inside) {
    local[v] = static_cast<int>(p.vertices.size());
    p.vertices.push_back(v);
  }
  p.num_inside = static_cast<int>(p.vertices.size());
  std::vector<int> halo;
  for (int f : faces)
    for (int k = 0; k < 3; ++k)
      if (local[hr_.F(f, k)] < 0) halo.push_back(hr_.F(f, k));
  std::sort(halo.begin(), halo.end());
  halo.erase(std::unique(halo.begin(), halo.end()), halo.end());
  for (int v : halo) {
    local[v] = static_cast<int>(p.vertices.size());
    p.vertices.push_back(v);
  }
  for (int i = 0; i < p.num_inside; ++i) p.inside_rows.push_back(i);

  p.faces = faces;
  p.local_faces.resize(static_cast<int>(faces.size()), 3);
  Faces fuv(static_cast<int>(faces.size()), 3);
  std::vector<int> local_face(static_cast<size_t>(hr_.F.rows()), -1);
  for (size_t i = 0; i < faces.size(); ++i) {
    local_face[faces[i]] = static_cast<int>(i);
    for (int k = 0; k < 3; ++k) p.local_faces(static_cast<int>(i), k) = local[hr_.F(faces[i], k)];
    fuv.row(static_cast<int>(i)) = hr_.FUV.row(faces[i]);
  }
  p.topo = make_topology(p.local_faces, static_cast<int>(p.vertices.size()), hr_.UV, fuv, normal_eps_);

  for (int v : p.vertices) {
    const int t = lr_tri_[v];
    if (t < 0) gdsr::fail("patches", "HR vertex " + std::to_string(v) + " has no LR triangle");
    p.lr_triangles.push_back(t);
  }
  std::sort(p.lr_triangles.begin(), p.lr_triangles.end());
  p.lr_triangles.erase(std::unique(p.lr_triangles.begin(), p.lr_triangles.end()), p.lr_triangles.end());

  const size_t npix = static_cast<size_t>(S) * S;
  p.pixel_corners.assign(npix * 3, 0);
  p.pixel_weights.assign(npix * 3, 0.0);
  p.mask.assign(npix, 0);
  for (int r = 0; r < S; ++r)
    for (int c = 0; c < S; ++c) {
      const size_t src = static_cast<size_t>(y0 + r) * W + x0 + c;
      const int t = raster_.tri[src];
      if (t < 0) continue;
      const size_t dst = static_cast<size_t>(r) * S + c;
      const int lf = local_face[t];
      p.mask[dst] = 1;
      p.garment_pixels.push_back(static_cast<int64_t>(dst));
      for (int k = 0; k < 3; ++k) {
        p.pixel_corners[3 * dst + k] = p.local_faces(lf, k);
        p.pixel_weights[3 * dst + k] = raster_.bary[3 * src + k];
      }
    }
  return p;
}

PatchBatch PatchSampler::sample(std::mt19937_64& rng) const {
  const int W = raster_.width, H = raster_.height, S = cfg_.size;
  std::vector<Patch> patches;
  if (cfg_.random_position) {
    std::uniform_int_distribution<size_t> pick(0, garment_pixels_.size() - 1);
    for (int n = 0; n < cfg_.count; ++n) {
      int bx = 0, by = 0;
      double best = -1;
      for (int tries = 0; tries < std::max(1, cfg_.max_tries); ++tries) {
        const int px = garment_pixels_[pick(rng)];
        const int x0 = std::clamp(px % W - S / 2, 0, W - S), y0 = std::clamp(px / W - S / 2, 0, H - S);
        const double cov = coverage(x0, y0);
        if (cov > best) {
          best = cov;
          bx = x0;
          by = y0;
        }
        if (cov >= cfg_.min_coverage) break;
      }
      patches.push_back(make_patch(bx, by));
    }
  } else {
    std::vector<int> ids(grid_.size());
    for (size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<int>(i);
    std::shuffle(ids.begin(), ids.end(), rng);
    const size_t n = std::min(ids.size(), static_cast<size_t>(cfg_.count));
    for (size_t i = 0; i < n; ++i) patches.push_back(make_patch(grid_[ids[i]][0], grid_[ids[i]][1]));
  }
  return make_batch(std::move(patches));
}

PatchBatch make_batch(std::vector<Patch> patches) {
  PatchBatch b;
  b.patches = std::move(patches);
  for (const Patch& p : b.patches) {
    b.vertices.insert(b.vertices.end(), p.vertices.begin(), p.vertices.end());
    b.lr_triangles.insert(b.lr_triangles.end(), p.lr_triangles.begin(), p.lr_triangles.end());
  }
  std::sort(b.vertices.begin(), b.vertices.end());
  b.vertices.erase(std::unique(b.vertices.begin(), b.vertices.end()), b.vertices.end());
  std::sort(b.lr_triangles.begin(), b.lr_triangles.end());
  b.lr_triangles.erase(std::unique(b.lr_triangles.begin(), b.lr_triangles.end()), b.lr_triangles.end());
  for (const Patch& p : b.patches) {
    ag::Index rows;
    rows.reserve(p.vertices.size());
    for (int v : p.vertices)
      rows.push_back(std::lower_bound(b.vertices.begin(), b.vertices.end(), v) - b.vertices.begin());
    b.rows.push_back(std::move(rows));
  }
  return b;
}

namespace {
template <class T> ag::Tensor<T> pixel_normals(const ag::Tensor<T>& n, const Patch& p) {
  if (n.dim() != 2 || n.cols() != 3 || n.rows() != static_cast<int64_t>(p.vertices.size()))
    gdsr::fail("patches", "normal map: normals must be [" + std::to_string(p.vertices.size()) + " x 3], got " +
                              ag::shape_str(n.shape()));
  const int64_t npix = static_cast<int64_t>(p.size) * p.size;
  std::vector<T> w(p.pixel_weights.begin(), p.pixel_weights.end());
  return ag::interpolate_rows(n, p.pixel_corners, ag::Tensor<T>::from({npix, 3}, std::move(w)));
}
}  // namespace

template <class T>
ag::Tensor<T> draw_normal_map(const ag::Tensor<T>& vertex_normals, const Patch& p, double background) {
  const int64_t S = p.size, npix = S * S;
  std::vector<T> offset(static_cast<size_t>(npix) * 3);
  for (int64_t i = 0; i < npix; ++i)
    for (int k = 0; k < 3; ++k) offset[3 * i + k] = static_cast<T>(p.mask[i] ? 0.5 : background);
  // Background rows interpolate nothing (weights 0), so their colour is the constant.
  const ag::Tensor<T> colour = ag::add(ag::mul_scalar(pixel_normals(vertex_normals, p), static_cast<T>(0.5)),
                                       ag::Tensor<T>::from({npix, 3}, std::move(offset)));
  return ag::reshape(ag::transpose(colour), {1, 3, S, S});
}

template <class T> ag::Tensor<T> normal_map_pixels(const ag::Tensor<T>& vertex_normals, const Patch& p) {
  if (p.garment_pixels.empty()) gdsr::fail("patches", "patch without garment pixels");
  const ag::Tensor<T> n = ag::index_select_rows(pixel_normals(vertex_normals, p), p.garment_pixels);
  return ag::add_scalar(ag::mul_scalar(n, static_cast<T>(0.5)), static_cast<T>(0.5));
}

template ag::Tensor<float> draw_normal_map<float>(const ag::Tensor<float>&, const Patch&, double);
template ag::Tensor<double> draw_normal_map<double>(const ag::Tensor<double>&, const Patch&, double);
template ag::Tensor<float> normal_map_pixels<float>(const ag::Tensor<float>&, const Patch&);
template ag::Tensor<double> normal_map_pixels<double>(const ag::Tensor<double>&, const Patch&);

namespace {

// The normal map of one patch of the batch (row k) as a CV_32FC3 image, RGB = xyz.
cv::Mat patch_normal_image(const PatchBatch& b, size_t k, const Points3& X) {
  const Patch& p = b.patches[k];
  Points3 local(static_cast<Eigen::Index>(p.vertices.size()), 3);
  for (size_t i = 0; i < p.vertices.size(); ++i) local.row(static_cast<Eigen::Index>(i)) = X.row(b.rows[k][i]);
  const ag::Tensor<double> map = draw_normal_map(vertex_normals(to_tensor<double>(local), p.topo), p);
  const auto& v = map.values();  // [1 x 3 x S x S], channel-major
  const int S = p.size;
  cv::Mat img(S, S, CV_32FC3);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < S; ++r)
      for (int col = 0; col < S; ++col)
        img.at<cv::Vec3f>(r, col)[c] = static_cast<float>(v[(static_cast<size_t>(c) * S + r) * S + col]);
  return img;
}

}  // namespace

double patch_normal_map_ssim(const PatchBatch& b, const Points3& pred, const Points3& truth) {
  const auto n = static_cast<Eigen::Index>(b.vertices.size());
  if (pred.rows() != n || truth.rows() != n)
    gdsr::fail("patch_normal_map_ssim", "positions for " + std::to_string(pred.rows()) + " and " +
                                            std::to_string(truth.rows()) + " vertices, the batch has " +
                                            std::to_string(n));
  if (b.patches.empty()) gdsr::fail("patch_normal_map_ssim", "the batch has no patch");
  double sum = 0;
  for (size_t k = 0; k < b.patches.size(); ++k) {
    const Patch& p = b.patches[k];
    cv::Mat mask(p.size, p.size, CV_8U);
    for (int i = 0; i < p.size * p.size; ++i) mask.data[i] = p.mask[static_cast<size_t>(i)] ? 255 : 0;
    sum += ssim_score(patch_normal_image(b, k, pred), patch_normal_image(b, k, truth), mask).garment;
  }
  return sum / static_cast<double>(b.patches.size());
}

}  // namespace gdsr

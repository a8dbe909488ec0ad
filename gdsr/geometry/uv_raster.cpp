#include "gdsr/geometry/uv_raster.hpp"

#include "gdsr/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace gdsr {
namespace {

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Barycentric weights of p in (a, b, c) from signed areas; area2 = cross2(b - a, c - a).
Eigen::Vector3d signed_bary(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c, double area2) {
  const double wa = cross2(b - p, c - p) / area2;
  const double wb = cross2(c - p, a - p) / area2;
  return {wa, wb, 1.0 - wa - wb};
}

constexpr double kInsideTol = 1e-12;

Vec2 uv_row(const Points2& UV, int i) { return UV.row(i).transpose(); }

}  // namespace

UVHit closest_on_triangle(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c) {
  const double area2 = cross2(b - a, c - a);
  UVHit hit;
  if (std::abs(area2) > 0) {
    Eigen::Vector3d w = signed_bary(p, a, b, c, area2);
    if (w.minCoeff() >= -kInsideTol) {
      w = w.cwiseMax(0.0);
      hit.bary = w / w.sum();
      hit.distance = 0;
      return hit;
    }
  }
  // Outside (or degenerate): the closest point lies on one of the edges.
  const Vec2 P[3] = {a, b, c};
  hit.distance = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const Vec2& s = P[k];
    const Vec2& t = P[(k + 1) % 3];
    const Vec2 d = t - s;
    const double len2 = d.squaredNorm();
    const double u = len2 > 0 ? std::clamp((p - s).dot(d) / len2, 0.0, 1.0) : 0.0;
    const double dist = (s + u * d - p).norm();
    if (dist < hit.distance) {
      hit.distance = dist;
      hit.bary.setZero();
      hit.bary(k) = 1.0 - u;
      hit.bary((k + 1) % 3) = u;
    }
  }
  return hit;
}

UVLocator::UVLocator(const Points2& UV, const Faces& FUV) : uv_(UV), f_(FUV) {
  if (UV.rows() == 0 || FUV.rows() == 0) gdsr::fail("uv locator", "empty UV layout");
  if (FUV.minCoeff() < 0 || FUV.maxCoeff() >= UV.rows()) gdsr::fail("uv locator", "UV face index out of range");
  if (!UV.allFinite()) gdsr::fail("uv locator", "NaN or infinite UV coordinate");
  const Vec2 lo = UV.colwise().minCoeff().transpose(), hi = UV.colwise().maxCoeff().transpose();
  double ext_sum = 0;
  for (int f = 0; f < FUV.rows(); ++f) {
    Eigen::Matrix<double, 3, 2> t;
    for (int k = 0; k < 3; ++k) t.row(k) = UV.row(FUV(f, k));
    ext_sum += (t.colwise().maxCoeff() - t.colwise().minCoeff()).maxCoeff();
  }
  const double size = std::max((hi - lo).maxCoeff(), 1e-300);
  cell_ = std::max(ext_sum / FUV.rows(), size / 2048.0);
  if (!(cell_ > 0)) cell_ = size;
  x0_ = lo.x();
  y0_ = lo.y();
  nx_ = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / cell_)) + 1);
  ny_ = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / cell_)) + 1);
  std::vector<std::vector<int>> cells(static_cast<size_t>(nx_) * ny_);
  for (int f = 0; f < FUV.rows(); ++f) {
    const Vec2 a = uv_row(UV, FUV(f, 0)), b = uv_row(UV, FUV(f, 1)), c = uv_row(UV, FUV(f, 2));
    const double area2 = cross2(b - a, c - a);
    const double scale2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (!(std::abs(area2) > 1e-12 * scale2)) continue;  // degenerate: never the answer
    const int cx0 = static_cast<int>((std::min({a.x(), b.x(), c.x()}) - x0_) / cell_);
    const int cx1 = static_cast<int>((std::max({a.x(), b.x(), c.x()}) - x0_) / cell_);
    const int cy0 = static_cast<int>((std::min({a.y(), b.y(), c.y()}) - y0_) / cell_);
    const int cy1 = static_cast<int>((std::max({a.y(), b.y(), c.y()}) - y0_) / cell_);
    for (int cy = std::max(cy0, 0); cy <= std::min(cy1, ny_ - 1); ++cy)
      for (int cx = std::max(cx0, 0); cx <= std::min(cx1, nx_ - 1); ++cx)
        cells[static_cast<size_t>(cy) * nx_ + cx].push_back(f);
  }
  start_.assign(cells.size() + 1, 0);
  for (size_t i = 0; i < cells.size(); ++i) start_[i + 1] = start_[i] + static_cast<int>(cells[i].size());
  items_.reserve(static_cast<size_t>(start_.back()));
  for (auto& c : cells) items_.insert(items_.end(), c.begin(), c.end());
  if (items_.empty()) gdsr::fail("uv locator", "every UV triangle is degenerate (zero area)");
}

void UVLocator::visit_cell(int cx, int cy, const Vec2& p, UVHit& best) const {
  if (cx < 0 || cy < 0 || cx >= nx_ || cy >= ny_) return;
  const size_t c = static_cast<size_t>(cy) * nx_ + cx;
  for (int k = start_[c]; k < start_[c + 1]; ++k) {
    const int f = items_[k];
    if (best.tri >= 0 && f >= best.tri && best.distance == 0) continue;  // keep the lowest inside id
    UVHit h = closest_on_triangle(p, uv_row(uv_, f_(f, 0)), uv_row(uv_, f_(f, 1)), uv_row(uv_, f_(f, 2)));
    if (best.tri < 0 || h.distance < best.distance || (h.distance == best.distance && f < best.tri)) {
      h.tri = f;
      best = h;
    }
  }
}

UVHit UVLocator::locate(const Vec2& p) const {
  if (!p.allFinite()) gdsr::fail("uv locator", "NaN or infinite query point");
  const int cx = std::clamp(static_cast<int>(std::floor((p.x() - x0_) / cell_)), 0, nx_ - 1);
  const int cy = std::clamp(static_cast<int>(std::floor((p.y() - y0_) / cell_)), 0, ny_ - 1);
  UVHit best;
  best.distance = std::numeric_limits<double>::infinity();
  for (int r = 0;; ++r) {
    if (r == 0) {
      visit_cell(cx, cy, p, best);
    } else {
      for (int d = -r; d <= r; ++d) {
        visit_cell(cx + d, cy - r, p, best);
        visit_cell(cx + d, cy + r, p, best);
      }
      for (int d = -r + 1; d <= r - 1; ++d) {
        visit_cell(cx - r, cy + d, p, best);
        visit_cell(cx + r, cy + d, p, best);
      }
    }
    // Lower bound on the distance to any cell outside the visited square.
    double bound = std::numeric_limits<double>::infinity();
    if (cx - r > 0) bound = std::min(bound, p.x() - (x0_ + (cx - r) * cell_));
    if (cx + r < nx_ - 1) bound = std::min(bound, x0_ + (cx + r + 1) * cell_ - p.x());
    if (cy - r > 0) bound = std::min(bound, p.y() - (y0_ + (cy - r) * cell_));
    if (cy + r < ny_ - 1) bound = std::min(bound, y0_ + (cy + r + 1) * cell_ - p.y());
    if (std::isinf(bound) || (best.tri >= 0 && best.distance <= bound)) break;
  }
  return best;
}

UVRaster rasterize_uv(const Points2& UV, const Faces& FUV, int width, int height, int padding) {
  if (UV.rows() == 0 || FUV.rows() == 0) gdsr::fail("uv raster", "empty UV layout");
  if (width <= 2 * padding || height <= 2 * padding) gdsr::fail("uv raster", "image too small for the padding");
  const Vec2 lo = UV.colwise().minCoeff().transpose(), hi = UV.colwise().maxCoeff().transpose();
  const Vec2 ext = hi - lo;
  if (!(ext.maxCoeff() > 0)) gdsr::fail("uv raster", "UV layout has zero extent");
  UVRaster r;
  r.width = width;
  r.height = height;
  r.scale =
      std::min((width - 2 * padding) / std::max(ext.x(), 1e-300), (height - 2 * padding) / std::max(ext.y(), 1e-300));
  const Vec2 mid = 0.5 * (lo + hi);
  r.u0 = mid.x() - 0.5 * width / r.scale;
  r.v0 = mid.y() - 0.5 * height / r.scale;
  r.tri.assign(static_cast<size_t>(width) * height, -1);
  r.bary.assign(static_cast<size_t>(width) * height * 3, 0.0f);
  for (int f = 0; f < FUV.rows(); ++f) {
    const Vec2 a = uv_row(UV, FUV(f, 0)), b = uv_row(UV, FUV(f, 1)), c = uv_row(UV, FUV(f, 2));
    const double area2 = cross2(b - a, c - a);
    if (area2 == 0) continue;
    const Vec2 pa = r.uv_to_pixel(a), pb = r.uv_to_pixel(b), pc = r.uv_to_pixel(c);
    const int i0 = std::max(0, static_cast<int>(std::floor(std::min({pa.x(), pb.x(), pc.x()}) - 0.5)));
    const int i1 = std::min(width - 1, static_cast<int>(std::ceil(std::max({pa.x(), pb.x(), pc.x()}) - 0.5)));
    const int j0 = std::max(0, static_cast<int>(std::floor(std::min({pa.y(), pb.y(), pc.y()}) - 0.5)));
    const int j1 = std::min(height - 1, static_cast<int>(std::ceil(std::max({pa.y(), pb.y(), pc.y()}) - 0.5)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const size_t px = static_cast<size_t>(j) * width + i;
        if (r.tri[px] >= 0) continue;
        const Eigen::Vector3d w = signed_bary(r.pixel_center_uv(i, j), a, b, c, area2);
        if (w.minCoeff() < -1e-9) continue;
        const Eigen::Vector3d wc = w.cwiseMax(0.0) / w.cwiseMax(0.0).sum();
        r.tri[px] = f;
        for (int k = 0; k < 3; ++k) r.bary[px * 3 + k] = static_cast<float>(wc(k));
      }
  }
  return r;
}

}  // namespace gdsr

// Point location in a flat UV layout and the per-pixel raster of a layout.
//
// UVLocator finds, for a 2-D point, the triangle containing it, or the nearest triangle
// when it lies outside every triangle, with barycentric coordinates (clamped to the
// triangle, so all >= 0 and summing to 1). Uniform grid over triangle bounding boxes,
// searched ring by ring with an exact stopping bound; O(1) per query on uniform meshes.
//
// UVRaster: width x height pixels; pixel (col i, row j) has its centre at
//   u = u0 + (i + 0.5) / scale,   v = v0 + (j + 0.5) / scale
// (scale in pixels per UV metre, identical in u and v; row j grows with v). The layout's
// bounding box is centred with `padding` empty pixels at least on each side. Pixels whose
// centre is inside no triangle have tri = -1 and bary = 0.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <array>
#include <vector>

namespace gdsr {

struct UVHit {
  int tri = -1;                   // triangle index
  Eigen::Vector3d bary{0, 0, 0};  // weights of the triangle's corners 0, 1, 2; sum 1
  double distance = 0;            // UV distance from the query to the triangle (0 inside)
};

// Closest point of triangle (a, b, c) to p, as barycentric weights and distance.
UVHit closest_on_triangle(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c);

class UVLocator {
 public:
  // UV: points x 2; FUV: triangles x 3. Triangles with (near) zero area are skipped.
  UVLocator(const Points2& UV, const Faces& FUV);
  UVHit locate(const Vec2& p) const;

 private:
  Points2 uv_;
  Faces f_;
  double x0_ = 0, y0_ = 0, cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<int> start_, items_;  // CSR: triangles overlapping each cell
  void visit_cell(int cx, int cy, const Vec2& p, UVHit& best) const;
};

struct UVRaster {
  int width = 0, height = 0;
  double scale = 1, u0 = 0, v0 = 0;  // pixel <-> UV mapping (see above)
  std::vector<int> tri;              // width*height, row-major (row j, col i) -> j*width+i
  std::vector<float> bary;           // width*height*3
  Vec2 pixel_center_uv(int col, int row) const { return {u0 + (col + 0.5) / scale, v0 + (row + 0.5) / scale}; }
  // Continuous pixel coordinates (col, row) of a UV point (pixel centres at k + 0.5).
  Vec2 uv_to_pixel(const Vec2& uv) const { return {(uv.x() - u0) * scale, (uv.y() - v0) * scale}; }
};

// Raster of the layout (UV, FUV); padding in pixels. Throws if the layout is empty or has
// zero extent.
UVRaster rasterize_uv(const Points2& UV, const Faces& FUV, int width = 1024, int height = 1024, int padding = 4);

}  // namespace gdsr

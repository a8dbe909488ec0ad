// Patch sampling for the fine (wrinkle) loss: square windows of the HR UV raster
// (default 80 x 80 pixels of the 1024 x 1024 raster), the HR vertices under them, the LR
// triangles whose wrinkle fields A must be evaluated for those vertices, and the
// differentiable normal-map drawing of a patch.
//
// A patch lists
//   - vertices: global HR vertex ids the model must predict. The first num_inside are the
//     corners of the HR triangles hit by the patch's pixels ("inside": position loss,
//     smoothness); with halo on, the rest are the other corners of every face around an
//     inside vertex, so the inside vertices' area-weighted normals are exact (the
//     reference computes them from the pixel faces only: halo off).
//   - local_faces / topo: those faces in local vertex numbering, with the UV rest shape.
//   - per pixel: local corner indices and barycentrics of its HR triangle (background
//     pixels: corners 0, weights 0, mask 0).
// Images are [N x 3 x S x S] (channel-major, row r = raster row y0 + r), colour
// 0.5 n + 0.5 on garment pixels and a constant background colour elsewhere, identical for
// prediction and ground truth. The interpolated normal is not renormalised (the
// reference's fixed raster interpolation).
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/geometry/geometry_ad.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "gdsr/geometry/uv_raster.hpp"

#include <array>
#include <random>
#include <vector>

namespace gdsr {

struct PatchConfig {
  int size = 80;                // window side, pixels
  int count = 8;                // patches per training step
  double min_coverage = 0.1;    // fraction of garment pixels a window must cover
  bool random_position = true;  // true: window centred on a random garment pixel (clamped to
                                // the raster); false: draw from a fixed non-overlapping grid
  bool halo = true;             // exact normals at the patch's vertices (see above)
  int max_tries = 64;           // random windows tried per patch before taking the best
};

struct Patch {
  int x0 = 0, y0 = 0, size = 0;  // pixel window [x0, x0 + size) x [y0, y0 + size)
  std::vector<int> vertices;     // global HR vertices, inside ones first (each part ascending)
  int num_inside = 0;
  ag::Index inside_rows;              // 0 .. num_inside-1
  std::vector<int> faces;             // global HR face of each local face
  Faces local_faces;                  // faces x 3 into `vertices`
  MeshTopology topo;                  // of local_faces (UV rest shape included)
  std::vector<int> lr_triangles;      // LR triangles needed by `vertices`, unique ascending
  ag::Index pixel_corners;            // size*size*3 local vertex indices (0 on background)
  std::vector<double> pixel_weights;  // size*size*3 barycentrics (0 on background)
  std::vector<char> mask;             // size*size: 1 garment, 0 background
  ag::Index garment_pixels;           // pixel indices (r * size + c) with mask 1
  int num_garment_pixels() const { return static_cast<int>(garment_pixels.size()); }
};

// Several patches evaluated together: the model predicts `vertices` once, each patch reads
// its rows.
struct PatchBatch {
  std::vector<Patch> patches;
  std::vector<int> vertices;      // union of the patches' vertices, ascending
  std::vector<int> lr_triangles;  // union of their LR triangles, ascending
  std::vector<ag::Index> rows;    // per patch: row in `vertices` of each patch.vertices[i]
};
PatchBatch make_batch(std::vector<Patch> patches);

class PatchSampler {
 public:
  // raster: the HR layout raster (tri = face of hr.F / hr.FUV). hr_vertex_lr_triangle: LR
  // triangle of each HR welded vertex (Correspondence::hr_from_lr.tri). normal_eps: as in
  // make_topology (<= 0: automatic from the whole HR layout). Throws if the raster is
  // smaller than a patch, has no garment pixel, or sizes disagree.
  PatchSampler(UVRaster raster, GarmentMesh hr, std::vector<int> hr_vertex_lr_triangle, PatchConfig cfg = {},
               double normal_eps = -1);

  // The patch with its top-left pixel at (x0, y0); throws when it leaves the raster.
  Patch make_patch(int x0, int y0) const;
  // cfg.count patches (distinct grid cells in grid mode, as far as the grid has them).
  PatchBatch sample(std::mt19937_64& rng) const;
  // Grid mode: top-left corners of the windows of the fixed grid with enough coverage.
  const std::vector<std::array<int, 2>>& grid() const { return grid_; }
  const PatchConfig& config() const { return cfg_; }
  const UVRaster& raster() const { return raster_; }
  double coverage(int x0, int y0) const;  // fraction of garment pixels in the window

 private:
  UVRaster raster_;
  GarmentMesh hr_;
  std::vector<int> lr_tri_;
  PatchConfig cfg_;
  double normal_eps_ = 0;
  std::vector<int> vf_offsets_, vf_items_;  // HR vertex -> faces (CSR)
  std::vector<int> garment_pixels_;         // raster pixel indices with a triangle
  std::vector<int> integral_;               // (W+1) x (H+1) summed garment-pixel table
  std::vector<std::array<int, 2>> grid_;
};

// The patch's normal map [1 x 3 x S x S] from per-vertex normals [patch.vertices x 3].
template <class T>
ag::Tensor<T> draw_normal_map(const ag::Tensor<T>& vertex_normals, const Patch& p, double background = 0.0);
// The colour rows of the garment pixels only, [num_garment_pixels x 3] (0.5 n + 0.5).
template <class T> ag::Tensor<T> normal_map_pixels(const ag::Tensor<T>& vertex_normals, const Patch& p);

// Mean over the batch's patches of the SSIM of their normal maps over garment pixels only
// (gdsr::ssim_score): validation's image figure. pred, truth: positions of b.vertices (same
// order), metres. Throws if the row counts differ from b.vertices.
double patch_normal_map_ssim(const PatchBatch& b, const Points3& pred, const Points3& truth);

}  // namespace gdsr

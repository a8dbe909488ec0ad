// Preview renderer: ray-cast (Embree) shaded images of triangle meshes, for looking at
// bodies and garments (wrinkles). Lambert shading from a light near the camera plus
// ambient, two-sided (open garment surfaces are lit from both sides), one colour per mesh.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace gdsr {

struct RenderOptions {
  int width = 512, height = 512;                    // pixels
  bool perspective = false;                         // false: orthographic
  double fov_deg = 30.0;                            // perspective: vertical field of view
  Vec3 view_dir = Vec3(0, 0, -1);                   // camera looks along this (default: from +z, the body's front)
  Vec3 up = Vec3(0, 1, 0);                          // image up
  double margin = 0.05;                             // framing margin, fraction of the framed half extent
  double ambient = 0.25;                            // ambient term in [0, 1]
  bool smooth = true;                               // interpolated vertex normals (false: flat faces)
  cv::Vec3b background = cv::Vec3b(255, 255, 255);  // BGR
  // Framing: when > 0, the orthographic half height (metres) / the perspective look-at box
  // is fixed instead of fitted, so several images share one camera.
  double ortho_half_height = 0.0;
  Vec3 center = Vec3::Zero();  // used with ortho_half_height > 0
};

// Camera fitted to the meshes: orthographic half extents are the largest projected half
// extent of the bounding box around its centre, times (1 + margin); perspective places the
// camera so the bounding sphere fits the smaller field of view.
// Returns a BGR image (CV_8UC3, height x width). colours: BGR per mesh (default palette if
// fewer than meshes). Throws on empty input, empty meshes or non-finite vertices.
cv::Mat render_meshes(const std::vector<TriMesh>& meshes, const std::vector<cv::Vec3b>& colours = {},
                      const RenderOptions& opt = {});

// Images side by side (same height after resizing to the tallest), each with its label
// written on top; white background.
cv::Mat side_by_side(const std::vector<cv::Mat>& images, const std::vector<std::string>& labels = {});

// cv::imwrite to "<path>.tmp.png" then rename to path. Throws on failure.
void write_png_atomic(const std::string& path, const cv::Mat& image);

}  // namespace gdsr

#include "gdsr/data/md_import.hpp"

#include "gdsr/error.hpp"

#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/geometry/uv_raster.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <unordered_map>

namespace gdsr {
namespace fs = std::filesystem;
namespace {

long last_number(const std::string& name) {
  long value = -1;
  for (size_t i = 0; i < name.size();) {
    if (std::isdigit(static_cast<unsigned char>(name[i]))) {
      size_t j = i;
      while (j < name.size() && std::isdigit(static_cast<unsigned char>(name[j]))) ++j;
      value = std::stol(name.substr(i, std::min<size_t>(j - i, 18)));
      i = j;
    } else {
      ++i;
    }
  }
  return value;
}

// Applies a weld map to a sequence: faces re-indexed (first frame), positions compacted.
void weld_sequence(std::vector<ObjData>& seq, const std::vector<int>& map, int count, const std::string& what) {
  for (int f = 0; f < seq[0].F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) seq[0].F(f, k) = map[seq[0].F(f, k)];
    if (seq[0].F(f, 0) == seq[0].F(f, 1) || seq[0].F(f, 1) == seq[0].F(f, 2) || seq[0].F(f, 0) == seq[0].F(f, 2))
      gdsr::fail("import-md", std::string(what) + ": welding collapses triangle " + std::to_string(f) +
                                  " (weld distance too large)");
  }
  for (ObjData& d : seq) {
    Points3 V(count, 3);
    for (int i = static_cast<int>(map.size()) - 1; i >= 0; --i) V.row(map[i]) = d.V.row(i);
    d.V = std::move(V);
  }
}

}  // namespace

std::vector<std::string> list_frame_objs(const std::string& dir) {
  if (!fs::is_directory(dir)) gdsr::fail(dir, "no such folder");
  std::vector<std::pair<long, std::string>> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext != ".obj") continue;
    files.emplace_back(last_number(e.path().stem().string()), e.path().string());
  }
  if (files.empty()) gdsr::fail(dir, "no .obj files in the folder");
  std::sort(files.begin(), files.end());
  std::vector<std::string> out;
  for (auto& f : files) out.push_back(f.second);
  return out;
}

std::vector<std::string> list_frame_sequence(const std::string& dir) {
  std::vector<std::string> paths = list_frame_objs(dir);
  long prev = -1, step = 0;
  for (size_t i = 0; i < paths.size(); ++i) {
    const long n = last_number(fs::path(paths[i]).stem().string());
    if (n < 0 && paths.size() > 1)
      gdsr::fail(paths[i], "no frame number in the file name (one OBJ per frame, numbered)");
    if (i == 1) step = n - prev;
    if (i >= 1 && (n == prev || n - prev != step))
      gdsr::fail(paths[i], n == prev ? "frame number " + std::to_string(n) + " appears twice"
                                     : "frame " + std::to_string(n) + " follows frame " + std::to_string(prev) +
                                           " (step " + std::to_string(step) + " before): missing frames");
    prev = n;
  }
  return paths;
}

std::vector<ObjData> read_frame_sequence(const std::vector<std::string>& paths, const std::string& where,
                                         const std::string& what, int& done, int total, const ProgressFn& progress) {
  std::vector<ObjData> out;
  for (const std::string& path : paths) {
    ObjData d = read_obj(path);
    if (!out.empty()) {
      if (d.V.rows() != out[0].V.rows())
        gdsr::fail(where, std::string(path) + ": " + std::to_string(d.V.rows()) + " vertices, the first " + what +
                              " frame has " + std::to_string(out[0].V.rows()) + " (vertex count mismatch)");
      if (d.F.rows() != out[0].F.rows() || d.F != out[0].F)
        gdsr::fail(where, std::string(path) + ": faces differ from the first " + what + " frame");
      d.F.resize(0, 3);  // only the first frame keeps faces
      d.FT.resize(0, 3);
    }
    d.VT.resize(0, 2);
    out.push_back(std::move(d));
    if (progress) progress(++done, total);
  }
  return out;
}

namespace {

// Frames are stored as float32: a coordinate beyond its range (after `scale`) would become
// inf in the dataset, so it is refused here, naming the file.
void check_float_range(const std::vector<ObjData>& frames, const std::vector<std::string>& paths, double scale) {
  for (size_t t = 0; t < frames.size(); ++t) {
    // (NaN and inf never get here: the OBJ reader refuses them.)
    const double m = frames[t].V.size() ? frames[t].V.cwiseAbs().maxCoeff() * scale : 0.0;
    if (!(m <= std::numeric_limits<float>::max())) {
      char v[32];
      std::snprintf(v, sizeof v, "%.3g", m);
      gdsr::fail(paths[t], std::string("coordinate of magnitude ") + v +
                               " (after --scale) is beyond the float32 range of a dataset (3.4e38)");
    }
  }
}

}  // namespace

std::vector<int> weld_map(const Points3& V, double eps, int& count) {
  if (!(eps > 0)) gdsr::fail("import-md", "weld distance must be positive");
  auto key = [&](long x, long y, long z) { return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791); };
  std::unordered_map<long, std::vector<int>> grid;
  std::vector<int> map(static_cast<size_t>(V.rows()), -1);
  count = 0;
  for (int i = 0; i < V.rows(); ++i) {
    const long cx = static_cast<long>(std::floor(V(i, 0) / eps)), cy = static_cast<long>(std::floor(V(i, 1) / eps)),
               cz = static_cast<long>(std::floor(V(i, 2) / eps));
    int rep = -1;
    for (long dx = -1; dx <= 1 && rep < 0; ++dx)
      for (long dy = -1; dy <= 1 && rep < 0; ++dy)
        for (long dz = -1; dz <= 1 && rep < 0; ++dz) {
          auto it = grid.find(key(cx + dx, cy + dy, cz + dz));
          if (it == grid.end()) continue;
          for (int j : it->second)
            if ((V.row(i) - V.row(j)).norm() <= eps) {
              rep = j;
              break;
            }
        }
    if (rep >= 0) {
      map[i] = map[rep];
    } else {
      map[i] = count++;
      grid[key(cx, cy, cz)].push_back(i);
    }
  }
  return map;
}

GarmentMesh garment_from_flat(const ObjData& flat, const ObjData& frame, const std::string& what) {
  if (flat.F.rows() != frame.F.rows())
    gdsr::fail(what, "the flattened OBJ has " + std::to_string(flat.F.rows()) + " triangles, the 3-D mesh " +
                         std::to_string(frame.F.rows()) + " (faces must correspond one to one)");
  // Drop the coordinate with the smallest extent: the pattern lies in the other two.
  const Eigen::RowVector3d ext = flat.V.colwise().maxCoeff() - flat.V.colwise().minCoeff();
  int drop = 0;
  ext.minCoeff(&drop);
  const int a = drop == 0 ? 1 : 0, b = drop == 2 ? 1 : 2;
  if (ext(drop) > 1e-3 * ext.maxCoeff()) gdsr::fail(what, "the flattened OBJ is not planar");
  ObjData merged;
  merged.V = frame.V;
  merged.F = frame.F;
  merged.VT.resize(flat.V.rows(), 2);
  merged.VT.col(0) = flat.V.col(a);
  merged.VT.col(1) = flat.V.col(b);
  merged.FT = flat.F;
  return garment_from_obj(merged, what);
}

Dataset import_md(const MdImportOptions& opt) {
  if (!(opt.scale > 0)) gdsr::fail("import-md", "scale must be positive");
  if (!(opt.fps > 0)) gdsr::fail("import-md", "fps must be positive");
  // Each folder's numbering first (a gap, a repeat or an unnumbered file names the file),
  // then the counts against each other.
  const std::vector<std::string> lr_paths = list_frame_sequence(opt.lr_dir), hr_paths = list_frame_sequence(opt.hr_dir);
  const std::vector<std::string> body_paths = opt.body_dir.empty() ? lr_paths : list_frame_sequence(opt.body_dir);
  const size_t n_lr = lr_paths.size(), n_hr = hr_paths.size(), n_body = body_paths.size();
  if (n_lr != n_hr || n_lr != n_body)
    gdsr::fail(
        "import-md",
        "mismatched frame counts: " + std::to_string(n_lr) + " LR (" + opt.lr_dir + "), " + std::to_string(n_hr) +
            " HR (" + opt.hr_dir + ")" +
            (opt.body_dir.empty() ? std::string() : ", " + std::to_string(n_body) + " body (" + opt.body_dir + ")") +
            " OBJ files");
  const int total = static_cast<int>(n_lr + n_hr + (opt.body_dir.empty() ? 0 : n_body));
  int done = 0;

  Dataset d;
  std::vector<ObjData> lr = read_frame_sequence(lr_paths, "import-md", "LR", done, total, opt.progress);
  std::vector<ObjData> hr = read_frame_sequence(hr_paths, "import-md", "HR", done, total, opt.progress);
  check_float_range(lr, lr_paths, opt.scale);
  check_float_range(hr, hr_paths, opt.scale);
  if (opt.weld > 0) {
    int n = 0;
    const std::vector<int> lm = weld_map(lr[0].V * opt.scale, opt.weld, n);
    weld_sequence(lr, lm, n, opt.lr_dir);
    const std::vector<int> hm = weld_map(hr[0].V * opt.scale, opt.weld, n);
    weld_sequence(hr, hm, n, opt.hr_dir);
  }
  d.lr = garment_from_flat(read_obj(opt.lr_uv), lr[0], opt.lr_uv);
  d.hr = garment_from_flat(read_obj(opt.hr_uv), hr[0], opt.hr_uv);
  for (GarmentMesh* g : {&d.lr, &d.hr}) {
    g->V *= opt.scale;
    g->UV *= opt.scale;
  }
  check_uv_layout(d.lr, opt.lr_uv);
  check_uv_layout(d.hr, opt.hr_uv);
  for (auto& f : lr) d.lr_frames.push_back(f.V * opt.scale);
  for (auto& f : hr) d.hr_frames.push_back(f.V * opt.scale);
  lr.clear();
  hr.clear();
  if (!opt.body_dir.empty()) {
    std::vector<ObjData> body = read_frame_sequence(body_paths, "import-md", "body", done, total, opt.progress);
    check_float_range(body, body_paths, opt.scale);
    d.body_faces = body[0].F;
    for (auto& f : body) d.body_frames.push_back(f.V * opt.scale);
  }

  d.corr = compute_correspondence(d.lr, d.hr);
  d.raster = rasterize_uv(d.hr.UV, d.hr.FUV, opt.raster_size, opt.raster_size);
  DatasetManifest& m = d.manifest;
  m.garment = opt.garment;
  m.source_motion = "marvelous-designer:" + opt.lr_dir;
  m.fps = opt.fps;
  m.lr_particle_distance = mean_edge_length(d.lr.V, d.lr.F);
  m.hr_particle_distance = mean_edge_length(d.hr.V, d.hr.F);
  m.sim_params = {{"source", "marvelous-designer"}, {"scale_to_m", opt.scale}, {"lr_dir", opt.lr_dir},
                  {"hr_dir", opt.hr_dir},           {"lr_uv", opt.lr_uv},      {"hr_uv", opt.hr_uv},
                  {"body_dir", opt.body_dir}};
  update_manifest_counts(d);
  validate_dataset(d, "import-md");
  return d;
}

}  // namespace gdsr

#include "gdsr/data/sequence_import.hpp"

#include "gdsr/data/md_import.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

namespace gdsr {

Dataset import_lr_sequence(const SequenceImportOptions& opt) {
  const std::string where = "infer";
  if (!(opt.scale > 0)) gdsr::fail(where, "--scale must be positive");
  if (!(opt.fps > 0)) gdsr::fail(where, "--fps must be positive");
  if (opt.hr_uv.empty() && opt.subdivide != 1 && opt.subdivide != 2)
    gdsr::fail(where, "--subdivide must be 1 or 2, not " + std::to_string(opt.subdivide));
  const std::vector<std::string> lr_paths = list_frame_sequence(opt.lr_dir);
  std::vector<std::string> body_paths;
  if (!opt.body_dir.empty()) {
    body_paths = list_frame_sequence(opt.body_dir);
    if (body_paths.size() != lr_paths.size())
      gdsr::fail(opt.body_dir, std::to_string(body_paths.size()) + " body OBJ files, but " +
                                   std::to_string(lr_paths.size()) + " LR frames in " + opt.lr_dir);
  }
  const int total = static_cast<int>(lr_paths.size() + body_paths.size());
  int done = 0;

  Dataset d;
  std::vector<ObjData> lr = read_frame_sequence(lr_paths, where, "LR", done, total, opt.progress);
  d.lr = garment_from_flat(read_obj(opt.lr_uv), lr[0], opt.lr_uv);
  d.lr.V *= opt.scale;
  d.lr.UV *= opt.scale;
  check_uv_layout(d.lr, opt.lr_uv);
  for (auto& f : lr) d.lr_frames.push_back(f.V * opt.scale);
  lr.clear();

  if (!opt.hr_uv.empty()) {
    d.hr = garment_from_obj(read_obj(opt.hr_uv), opt.hr_uv);
    d.hr.V *= opt.scale;
    d.hr.UV *= opt.scale;
    check_uv_layout(d.hr, opt.hr_uv);
  } else {
    d.hr = d.lr;
    for (int k = 0; k < opt.subdivide; ++k) d.hr = subdivide_midpoint(d.hr);
  }
  if (!body_paths.empty()) {
    std::vector<ObjData> body = read_frame_sequence(body_paths, where, "body", done, total, opt.progress);
    d.body_faces = body[0].F;
    for (auto& f : body) d.body_frames.push_back(f.V * opt.scale);
  }

  d.corr = compute_correspondence(d.lr, d.hr);
  DatasetManifest& m = d.manifest;
  m.garment = "user";
  m.source_motion = "lr-dir:" + opt.lr_dir;
  m.fps = opt.fps;
  m.lr_particle_distance = mean_edge_length(d.lr.V, d.lr.F);
  m.hr_particle_distance = mean_edge_length(d.hr.V, d.hr.F);
  m.sim_params = {{"source", "lr-dir"},  {"scale_to_m", opt.scale}, {"lr_dir", opt.lr_dir},   {"lr_uv", opt.lr_uv},
                  {"hr_uv", opt.hr_uv}, {"subdivide", opt.subdivide}, {"body_dir", opt.body_dir}};
  update_manifest_counts(d);
  return d;
}

}  // namespace gdsr

#include "infer/export_rollout.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"

#include <filesystem>

namespace gdsr {

Points2 raster_texcoords(const UVRaster& raster, const Points2& UV) {
  Points2 T(UV.rows(), 2);
  for (Eigen::Index i = 0; i < UV.rows(); ++i) {
    const Vec2 px = raster.uv_to_pixel(UV.row(i).transpose());
    T(i, 0) = px.x() / raster.width;
    T(i, 1) = px.y() / raster.height;
  }
  return T;
}

nlohmann::json export_rollout(const std::string& dir, const Dataset& d, const std::vector<Points3>& G, int first_frame,
                              const RolloutExportOptions& opt) {
  const int T = static_cast<int>(d.lr_frames.size());
  const int n = static_cast<int>(G.size());
  if (n == 0) gdsr::fail(dir, "the roll-out has no frames to export");
  if (first_frame < 0 || first_frame + n > T)
    gdsr::fail(dir, "roll-out frames " + std::to_string(first_frame) + ".." + std::to_string(first_frame + n - 1) +
                        " are outside the dataset's " + std::to_string(T) + " frames");
  SequenceExportOptions f = opt.formats;
  f.first_frame = first_frame;
  f.fps = d.manifest.fps;
  const auto slice = [&](const std::vector<Points3>& all) {
    return std::vector<Points3>(all.begin() + first_frame, all.begin() + first_frame + n);
  };
  nlohmann::json seqs = nlohmann::json::array();
  SequenceExportOptions hr_f = f;
  if (d.raster.width > 0) hr_f.texcoord = raster_texcoords(d.raster, d.hr.UV);
  if (opt.lr) seqs.push_back(export_sequence(dir, "lr", d.lr, slice(d.lr_frames), f));
  if (opt.gdsr) seqs.push_back(export_sequence(dir, "gdsr", d.hr, G, hr_f));
  if (opt.hr) {
    if (static_cast<int>(d.hr_frames.size()) < first_frame + n)
      gdsr::fail(dir, "the dataset has no HR simulation to export");
    seqs.push_back(export_sequence(dir, "hr", d.hr, slice(d.hr_frames), hr_f));
  }
  const nlohmann::json j{{"dataset", d.manifest.garment},
                         {"fps", d.manifest.fps},
                         {"first_frame", first_frame},
                         {"frames", n},
                         {"sequences", seqs}};
  write_file_atomic((std::filesystem::path(dir) / "export.json").string(), j.dump(2));
  return j;
}

}  // namespace gdsr

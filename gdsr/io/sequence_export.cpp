#include "gdsr/io/sequence_export.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/io/gltf_export.hpp"
#include "gdsr/io/point_cache.hpp"

#include <cstdio>
#include <filesystem>

namespace gdsr {

nlohmann::json export_sequence(const std::string& dir, const std::string& name, const GarmentMesh& mesh,
                               const std::vector<Points3>& frames, const SequenceExportOptions& opt) {
  namespace fs = std::filesystem;
  if (frames.empty()) gdsr::fail(dir, "no frames to export for " + name);
  if (opt.obj_every < 1) gdsr::fail(dir, "obj_every must be at least 1");
  for (size_t k = 0; k < frames.size(); ++k) {
    if (frames[k].rows() != mesh.V.rows())
      gdsr::fail(dir, name + " frame " + std::to_string(k) + " has " + std::to_string(frames[k].rows()) +
                          " vertices, the mesh " + std::to_string(mesh.V.rows()));
    if (!frames[k].allFinite()) gdsr::fail(dir, name + " frame " + std::to_string(k) + " has a non-finite position");
  }
  fs::create_directories(dir);
  nlohmann::json j{{"name", name},           {"vertices", mesh.V.rows()}, {"uv_vertices", mesh.UV.rows()},
                   {"faces", mesh.F.rows()}, {"frames", frames.size()},   {"first_frame", opt.first_frame},
                   {"fps", opt.fps}};
  if (opt.gltf) {
    GltfOptions g;
    g.fps = opt.fps;
    g.name = name;
    g.texcoord = opt.texcoord;
    write_gltf_sequence((fs::path(dir) / (name + ".gltf")).string(), mesh, frames, g);
    j["gltf"] = name + ".gltf";
    j["gltf_buffer"] = name + ".bin";
  }
  GarmentMesh posed = mesh;
  if (opt.pc2) {
    write_pc2((fs::path(dir) / (name + ".pc2")).string(), frames, 0.0f, 1.0f);
    posed.V = frames[0];
    write_obj((fs::path(dir) / (name + "_rest.obj")).string(), posed);
    j["pc2"] = name + ".pc2";
    j["rest_obj"] = name + "_rest.obj";
  }
  if (opt.obj) {
    fs::create_directories(fs::path(dir) / "obj");
    nlohmann::json list = nlohmann::json::array();
    for (size_t k = 0; k < frames.size(); k += static_cast<size_t>(opt.obj_every)) {
      char number[16];
      std::snprintf(number, sizeof number, "%05d", opt.first_frame + static_cast<int>(k));
      const std::string file = "obj/" + name + "_" + number + ".obj";
      posed.V = frames[k];
      write_obj((fs::path(dir) / file).string(), posed);
      list.push_back(file);
    }
    j["obj"] = list;
  }
  return j;
}

}  // namespace gdsr

#include "gdsr/io/gltf_export.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace gdsr {

namespace {

constexpr int kFloat = 5126, kUint = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// The binary buffer and its views / accessors, appended section by section.
struct GltfBuilder {
  std::string bin;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();

  int add_view(const void* data, size_t bytes, int target) {
    const size_t offset = bin.size();
    bin.append(static_cast<const char*>(data), bytes);
    nlohmann::json v{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (target) v["target"] = target;
    views.push_back(v);
    return static_cast<int>(views.size()) - 1;
  }
  // count elements of `type` ("SCALAR", "VEC2", "VEC3") with `comps` floats each; min/max per component.
  int add_floats(const std::vector<float>& x, int comps, const char* type, int target, bool bounds) {
    const int view = add_view(x.data(), x.size() * sizeof(float), target);
    nlohmann::json a{{"bufferView", view}, {"componentType", kFloat}, {"count", x.size() / comps}, {"type", type}};
    if (bounds) {
      std::vector<float> lo(comps, 0), hi(comps, 0);
      if (!x.empty())
        for (int c = 0; c < comps; ++c) {
          lo[c] = hi[c] = x[c];
          for (size_t i = c; i < x.size(); i += comps) lo[c] = std::min(lo[c], x[i]), hi[c] = std::max(hi[c], x[i]);
        }
      a["min"] = lo;
      a["max"] = hi;
    }
    accessors.push_back(a);
    return static_cast<int>(accessors.size()) - 1;
  }
  int add_indices(const std::vector<uint32_t>& idx) {
    const int view = add_view(idx.data(), idx.size() * sizeof(uint32_t), kElementArrayBuffer);
    accessors.push_back({{"bufferView", view}, {"componentType", kUint}, {"count", idx.size()}, {"type", "SCALAR"}});
    return static_cast<int>(accessors.size()) - 1;
  }
};

// Positions of the glTF (per UV vertex) mesh for one frame, minus `base` when given.
std::vector<float> split_positions(const GarmentMesh& mesh, const Points3& V, const std::vector<float>* base) {
  const size_t n = mesh.uv_to_vertex.size();
  std::vector<float> out(3 * n);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const float x = static_cast<float>(V(mesh.uv_to_vertex[i], c));
      out[3 * i + c] = base ? x - (*base)[3 * i + c] : x;
    }
  return out;
}

}  // namespace

Points2 normalized_texcoords(const Points2& UV) {
  Points2 T(UV.rows(), 2);
  if (UV.rows() == 0) return T;
  const Vec2 lo = UV.colwise().minCoeff().transpose(), hi = UV.colwise().maxCoeff().transpose();
  const double ext = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1e-12});
  for (int i = 0; i < UV.rows(); ++i) {
    T(i, 0) = (UV(i, 0) - lo.x()) / ext;
    T(i, 1) = 1.0 - (UV(i, 1) - lo.y()) / ext;
  }
  return T;
}

void write_gltf_sequence(const std::string& gltf_path, const GarmentMesh& mesh, const std::vector<Points3>& frames,
                         const GltfOptions& opt) {
  namespace fs = std::filesystem;
  const fs::path path(gltf_path);
  if (path.extension() != ".gltf") gdsr::fail(gltf_path, "a glTF export path must end in .gltf");
  if (frames.empty()) gdsr::fail(gltf_path, "no frames to export");
  if (!(opt.fps > 0)) gdsr::fail(gltf_path, "fps must be positive");
  if (mesh.uv_to_vertex.size() != static_cast<size_t>(mesh.UV.rows()) || mesh.FUV.rows() != mesh.F.rows())
    gdsr::fail(gltf_path, "the garment mesh has no consistent UV layout");
  if (opt.texcoord.rows() != 0 && opt.texcoord.rows() != mesh.UV.rows())
    gdsr::fail(gltf_path, "texcoord has " + std::to_string(opt.texcoord.rows()) + " rows, the mesh " +
                              std::to_string(mesh.UV.rows()) + " UV vertices");
  for (size_t k = 0; k < frames.size(); ++k) {
    if (frames[k].rows() != mesh.V.rows())
      gdsr::fail(gltf_path, "frame " + std::to_string(k) + " has " + std::to_string(frames[k].rows()) +
                                " vertices, the mesh " + std::to_string(mesh.V.rows()));
    if (!frames[k].allFinite()) gdsr::fail(gltf_path, "frame " + std::to_string(k) + " has a non-finite position");
  }

  GltfBuilder b;
  std::vector<uint32_t> idx(static_cast<size_t>(mesh.FUV.size()));
  for (Eigen::Index f = 0; f < mesh.FUV.rows(); ++f)
    for (int c = 0; c < 3; ++c) idx[3 * f + c] = static_cast<uint32_t>(mesh.FUV(f, c));
  const int a_idx = b.add_indices(idx);
  const Points2 tc = opt.texcoord.rows() ? opt.texcoord : normalized_texcoords(mesh.UV);
  std::vector<float> tcf(2 * static_cast<size_t>(tc.rows()));
  for (Eigen::Index i = 0; i < tc.rows(); ++i)
    tcf[2 * i] = static_cast<float>(tc(i, 0)), tcf[2 * i + 1] = static_cast<float>(tc(i, 1));
  const int a_tc = b.add_floats(tcf, 2, "VEC2", kArrayBuffer, false);
  const std::vector<float> base = split_positions(mesh, frames[0], nullptr);
  const int a_pos = b.add_floats(base, 3, "VEC3", kArrayBuffer, true);

  const size_t T = frames.size(), n_targets = T - 1;
  nlohmann::json targets = nlohmann::json::array(), names = nlohmann::json::array();
  for (size_t k = 1; k < T; ++k) {
    const int a_target = b.add_floats(split_positions(mesh, frames[k], &base), 3, "VEC3", kArrayBuffer, true);
    targets.push_back(nlohmann::json{{"POSITION", a_target}});
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05zu", k);
    names.push_back(name);
  }

  nlohmann::json prim{
      {"attributes", {{"POSITION", a_pos}, {"TEXCOORD_0", a_tc}}}, {"indices", a_idx}, {"material", 0}, {"mode", 4}};
  nlohmann::json gmesh{{"name", opt.name}};
  const nlohmann::json material{
      {"name", opt.name + "_cloth"},
      {"doubleSided", true},
      {"pbrMetallicRoughness", {{"baseColorFactor", opt.rgba}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.8}}}};
  nlohmann::json gltf{{"asset", {{"version", "2.0"}, {"generator", "gdsr"}}}, {"scene", 0}};
  gltf["scenes"] = nlohmann::json::array({nlohmann::json{{"nodes", nlohmann::json::array({0})}}});
  gltf["nodes"] = nlohmann::json::array({nlohmann::json{{"mesh", 0}, {"name", opt.name}}});
  gltf["materials"] = nlohmann::json::array({material});
  if (n_targets > 0) {
    prim["targets"] = targets;
    gmesh["weights"] = std::vector<float>(n_targets, 0.0f);
    gmesh["extras"] = {{"targetNames", names}};
    // Keyframe k at k / fps: all weights 0 at frame 0, then one-hot on target k.
    std::vector<float> times(T), weights(T * n_targets, 0.0f);
    for (size_t k = 0; k < T; ++k) times[k] = static_cast<float>(k / opt.fps);
    for (size_t k = 1; k < T; ++k) weights[k * n_targets + (k - 1)] = 1.0f;
    const int a_t = b.add_floats(times, 1, "SCALAR", 0, true);
    const int a_w = b.add_floats(weights, 1, "SCALAR", 0, false);
    const nlohmann::json channel{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}};
    const nlohmann::json sampler{{"input", a_t}, {"output", a_w}, {"interpolation", "LINEAR"}};
    nlohmann::json anim{{"name", opt.name + "_sequence"}};
    anim["channels"] = nlohmann::json::array({channel});
    anim["samplers"] = nlohmann::json::array({sampler});
    gltf["animations"] = nlohmann::json::array({anim});
  }
  gmesh["primitives"] = nlohmann::json::array({prim});
  gltf["meshes"] = nlohmann::json::array({gmesh});
  gltf["accessors"] = b.accessors;
  gltf["bufferViews"] = b.views;
  const fs::path bin_path = fs::path(path).replace_extension(".bin");
  gltf["buffers"] =
      nlohmann::json::array({nlohmann::json{{"uri", bin_path.filename().string()}, {"byteLength", b.bin.size()}}});
  write_file_atomic(bin_path.string(), b.bin);
  write_file_atomic(gltf_path, gltf.dump(1));
}

}  // namespace gdsr

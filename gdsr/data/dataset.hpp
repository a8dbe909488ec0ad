// The on-disk dataset of one garment on one motion (docs/dataset-format.md): canonical LR
// and HR meshes with UV, LR / HR / body frames, correspondences and the HR UV raster.
// Positions in metres, time in seconds. Writing is atomic per folder (DIR.tmp, then
// rename); loading validates everything and throws one-line errors naming file and cause.
#pragma once

#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "gdsr/geometry/uv_raster.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace gdsr {

constexpr int kDatasetVersion = 1;

struct DatasetManifest {
  int version = kDatasetVersion;
  std::string garment;
  std::string source_motion;  // motion file or "marvelous-designer:<dir>"
  int layers = 1;
  double lr_particle_distance = 0.03;  // metres
  double hr_particle_distance = 0.01;  // metres
  double fps = 30;                     // frames per second
  int frames = 0;                      // T
  int rest_blend_frames = 0;           // leading frames blending from the rest pose
  int lr_vertices = 0, lr_faces = 0, lr_uv_vertices = 0;
  int hr_vertices = 0, hr_faces = 0, hr_uv_vertices = 0;
  int body_vertices = 0, body_faces = 0;                 // 0 when the dataset has no body
  nlohmann::json sim_params = nlohmann::json::object();  // generator settings, free form
  nlohmann::json stats = nlohmann::json::object();       // measured figures, free form
  // Validity figures (gdsr/data/validity.hpp, docs/dataset-format.md): written by
  // `gdsr data make`; empty (and absent from the file) for datasets made without them.
  nlohmann::json validity = nlohmann::json::object();
};

struct Dataset {
  DatasetManifest manifest;
  GarmentMesh lr, hr;                // canonical (rest) meshes, welded, with UV and layers
  std::vector<Points3> lr_frames;    // T x (lr_vertices x 3)
  std::vector<Points3> hr_frames;    // T x (hr_vertices x 3)
  std::vector<Points3> body_frames;  // T x (body_vertices x 3); empty without a body
  Faces body_faces;                  // body_faces x 3
  Correspondence corr;
  UVRaster raster;  // HR UV layout, typically 1024 x 1024
  bool has_body() const { return !body_frames.empty(); }
};

// Fills the count fields of the manifest from the data (vertices, faces, frames, layers).
void update_manifest_counts(Dataset& d);

// Throws if anything is inconsistent: counts vs manifest, frame counts, NaN/inf positions,
// degenerate UV triangles, out-of-range indices, correspondence sizes. `where` prefixes
// the messages (usually the folder).
void validate_dataset(const Dataset& d, const std::string& where);

// Throws if a UV triangle has (near) zero area or collinear corners, or an index is bad.
void check_uv_layout(const GarmentMesh& g, const std::string& what);

// Checks that `dir` may be written as a dataset folder, before any work is done: it does not
// exist, or it is a gdsr dataset (has manifest.json). An existing regular file or a folder
// that is not a dataset is refused (never deleted). A leftover dir + ".old.<pid>" from a
// replace that was killed between its renames, with no `dir`, is renamed back to `dir` (a note
// on stderr says so).
void check_dataset_out(const std::string& dir);

// Writes the folder `dir` atomically: everything goes to dir + ".tmp.<pid>"; an existing
// dataset is moved to dir + ".old.<pid>", the new one renamed in, then the old one removed
// (see check_dataset_out for a kill between the renames).
void write_dataset(const std::string& dir, const Dataset& d);

struct LoadOptions {
  bool frames = true;  // false: meshes, correspondences and raster only
  bool verify_checksums = true;
};
Dataset load_dataset(const std::string& dir, const LoadOptions& opt = {});
DatasetManifest read_manifest(const std::string& path);
// The same on the file's text; `path` names the file in errors.
DatasetManifest parse_manifest(const std::string& text, const std::string& path);

// ---- binary arrays (".bin"): see docs/dataset-format.md ----
enum class DType : uint32_t { f32 = 1, i32 = 2, f64 = 3 };
struct Array {
  DType dtype = DType::f32;
  std::vector<uint64_t> dims;
  std::string bytes;  // little-endian payload
  uint64_t count() const;
};
uint64_t fnv1a64(const char* data, size_t n);
void write_array(const std::string& path, const Array& a);
Array read_array(const std::string& path, bool verify_checksum = true);
// The same on the file's bytes; `path` names the file in errors.
Array parse_array(const std::string& bytes, const std::string& path, bool verify_checksum = true);

// T frames of N x 3 positions <-> a float32 T x N x 3 array. Throws on ragged frames.
Array frames_to_array(const std::vector<Points3>& frames);
std::vector<Points3> array_to_frames(const Array& a, const std::string& what);

}  // namespace gdsr

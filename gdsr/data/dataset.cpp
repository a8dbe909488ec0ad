#include "gdsr/data/dataset.hpp"

#include "gdsr/error.hpp"

#include "nn/checkpoint.hpp"

#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/model/json_value.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

namespace gdsr {
namespace fs = std::filesystem;
namespace {

constexpr int kMaxLayers = 64;
constexpr char kMagic[8] = {'G', 'D', 'S', 'R', 'A', 'R', 'R', '1'};

// Why `path` did not open: missing, a folder, or the system's reason (permission denied, ...).
[[noreturn]] void fail_to_open(const std::string& path) {
  const int err = errno;
  std::error_code ec;
  if (!fs::exists(path, ec)) gdsr::fail("dataset", "missing file " + path);
  if (fs::is_directory(path, ec)) gdsr::fail("dataset", path + " is a folder, not a file");
  gdsr::fail("dataset", "cannot read " + path + ": " + std::strerror(err ? err : EACCES));
}

size_t dtype_size(DType t) { return t == DType::f64 ? 8 : 4; }

std::string join(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

template <class T> void put(std::string& s, const T& v) { s.append(reinterpret_cast<const char*>(&v), sizeof(T)); }

template <class T> Array make_array(DType t, std::vector<uint64_t> dims, const T* data) {
  Array a;
  a.dtype = t;
  a.dims = std::move(dims);
  a.bytes.assign(reinterpret_cast<const char*>(data), a.count() * sizeof(T));
  return a;
}

void expect_shape(const Array& a, DType t, const std::vector<uint64_t>& dims, const std::string& what) {
  auto str = [](const std::vector<uint64_t>& d) {
    std::string s;
    for (size_t i = 0; i < d.size(); ++i) s += (i ? " x " : "") + std::to_string(d[i]);
    return s.empty() ? std::string("scalar") : s;
  };
  if (a.dtype != t) gdsr::fail("dataset", std::string(what) + ": wrong element type");
  if (a.dims != dims) gdsr::fail("dataset", std::string(what) + ": shape " + str(a.dims) + ", expected " + str(dims));
}

template <class T> const T* data_of(const Array& a) { return reinterpret_cast<const T*>(a.bytes.data()); }

std::vector<int> to_ints(const Array& a) {
  const int32_t* p = data_of<int32_t>(a);
  return std::vector<int>(p, p + a.count());
}

Array ints_array(const std::vector<int>& v, std::vector<uint64_t> dims) {
  std::vector<int32_t> w(v.begin(), v.end());
  return make_array(DType::i32, std::move(dims), w.data());
}

Array faces_array(const Faces& F) {
  std::vector<int32_t> w(F.data(), F.data() + F.size());
  return make_array(DType::i32, {static_cast<uint64_t>(F.rows()), 3}, w.data());
}

Faces array_faces(const Array& a) {
  Faces F(static_cast<long>(a.dims[0]), 3);
  const int32_t* p = data_of<int32_t>(a);
  for (long i = 0; i < F.size(); ++i) F.data()[i] = p[i];
  return F;
}

Array bary_array(const BaryMap& m) {
  return make_array(DType::f64, {static_cast<uint64_t>(m.size()), 3}, m.bary.data());
}

// Barycentric weights as the writers make them: finite, summing to 1, and each within
// [-1, 2] (a point at most about one triangle outside its triangle).
void check_bary_row(double b0, double b1, double b2, double tol, const std::string& path, size_t row) {
  const bool ok = std::isfinite(b0) && std::isfinite(b1) && std::isfinite(b2) && std::abs(b0 + b1 + b2 - 1) <= tol &&
                  std::min({b0, b1, b2}) >= -1 && std::max({b0, b1, b2}) <= 2;
  if (!ok)
    gdsr::fail("dataset", path + ": row " + std::to_string(row) +
                              " is not barycentric weights (NaN, out of range or not summing to 1)");
}

void check_index_range(const std::vector<int>& v, int lo, int end, const std::string& path, const char* what) {
  for (size_t i = 0; i < v.size(); ++i)
    if (v[i] < lo || v[i] >= end)
      gdsr::fail("dataset", path + ": entry " + std::to_string(i) + " is " + what + " " + std::to_string(v[i]) +
                                ", outside " + std::to_string(lo) + ".." + std::to_string(end - 1));
}

BaryMap read_bary(const std::string& dir, const std::string& stem, int n, int faces, bool verify) {
  BaryMap m;
  const std::string tp = join(dir, stem + "_tri.bin"), bp = join(dir, stem + "_bary.bin");
  const Array t = read_array(tp, verify);
  expect_shape(t, DType::i32, {static_cast<uint64_t>(n)}, tp);
  const Array b = read_array(bp, verify);
  expect_shape(b, DType::f64, {static_cast<uint64_t>(n), 3}, bp);
  m.tri = to_ints(t);
  check_index_range(m.tri, 0, faces, tp, "triangle");
  m.bary = Eigen::Map<const Bary>(data_of<double>(b), n, 3);
  for (int i = 0; i < n; ++i) check_bary_row(m.bary(i, 0), m.bary(i, 1), m.bary(i, 2), 1e-6, bp, i);
  return m;
}

// Positions in metres; anything beyond 10 km is a broken file, not a garment.
constexpr double kMaxCoordinate = 1e4;

std::vector<Points3> read_frames(const std::string& path, bool verify) {
  std::vector<Points3> f = array_to_frames(read_array(path, verify), path);
  for (size_t t = 0; t < f.size(); ++t)
    for (long i = 0; i < f[t].rows(); ++i)
      if (!f[t].row(i).allFinite() || f[t].row(i).cwiseAbs().maxCoeff() > kMaxCoordinate)
        gdsr::fail("dataset", path + ": frame " + std::to_string(t) + " vertex " + std::to_string(i) +
                                  " is NaN, infinite or beyond 10 km");
  return f;
}

void check_finite_frames(const std::vector<Points3>& frames, const std::string& what) {
  for (size_t t = 0; t < frames.size(); ++t)
    for (long i = 0; i < frames[t].rows(); ++i)
      if (!frames[t].row(i).allFinite())
        gdsr::fail("dataset", std::string(what) + ": NaN or infinite position at frame " + std::to_string(t) +
                                  " vertex " + std::to_string(i));
}

void check_frames(const std::vector<Points3>& frames, int n, int T, const std::string& what) {
  if (static_cast<int>(frames.size()) != T)
    gdsr::fail("dataset", std::string(what) + ": " + std::to_string(frames.size()) + " frames, expected " +
                              std::to_string(T) + " (mismatched frame counts)");
  for (size_t t = 0; t < frames.size(); ++t)
    if (frames[t].rows() != n)
      gdsr::fail("dataset", std::string(what) + ": frame " + std::to_string(t) + " has " +
                                std::to_string(frames[t].rows()) + " vertices, expected " + std::to_string(n) +
                                " (vertex count mismatch)");
  check_finite_frames(frames, what);
}

void check_garment(const GarmentMesh& g, const std::string& what) {
  if (g.V.rows() == 0 || g.F.rows() == 0) gdsr::fail("dataset", std::string(what) + ": empty mesh");
  if (!g.V.allFinite()) gdsr::fail("dataset", std::string(what) + ": NaN or infinite vertex position");
  if (g.F.minCoeff() < 0 || g.F.maxCoeff() >= g.V.rows())
    gdsr::fail("dataset", std::string(what) + ": face index out of range");
  if (g.FUV.rows() != g.F.rows()) gdsr::fail("dataset", std::string(what) + ": UV face count differs from face count");
  if (static_cast<long>(g.uv_to_vertex.size()) != g.UV.rows())
    gdsr::fail("dataset", std::string(what) + ": uv_to_vertex size differs from UV count");
  if (!g.layer.empty() && static_cast<long>(g.layer.size()) != g.V.rows())
    gdsr::fail("dataset", std::string(what) + ": layer ids do not match vertices");
  check_uv_layout(g, what);
}

nlohmann::json manifest_json(const DatasetManifest& m, const UVRaster& r) {
  nlohmann::json j;
  j["version"] = m.version;
  j["garment"] = m.garment;
  j["source_motion"] = m.source_motion;
  j["layers"] = m.layers;
  j["particle_distance_m"] = {{"lr", m.lr_particle_distance}, {"hr", m.hr_particle_distance}};
  j["fps"] = m.fps;
  j["frames"] = m.frames;
  j["rest_blend_frames"] = m.rest_blend_frames;
  j["lr"] = {{"vertices", m.lr_vertices}, {"faces", m.lr_faces}, {"uv_vertices", m.lr_uv_vertices}};
  j["hr"] = {{"vertices", m.hr_vertices}, {"faces", m.hr_faces}, {"uv_vertices", m.hr_uv_vertices}};
  j["body"] = {{"vertices", m.body_vertices}, {"faces", m.body_faces}};
  j["uv_raster"] = {{"width", r.width}, {"height", r.height}, {"scale", r.scale}, {"u0", r.u0}, {"v0", r.v0}};
  j["sim_params"] = m.sim_params;
  j["stats"] = m.stats;
  if (!m.validity.empty()) j["validity"] = m.validity;
  return j;
}

template <class T> T get(const nlohmann::json& j, const std::string& key, const std::string& path) {
  const nlohmann::json* p = &j;
  std::string rest = key;
  while (true) {
    const size_t dot = rest.find('.');
    const std::string k = rest.substr(0, dot);
    if (!p->is_object() || !p->contains(k)) gdsr::fail("dataset", std::string(path) + ": missing key '" + key + "'");
    p = &(*p)[k];
    if (dot == std::string::npos) break;
    rest = rest.substr(dot + 1);
  }
  try {
    return json_value<T>(*p);
  } catch (const std::exception&) {
    gdsr::fail("dataset", std::string(path) + ": key '" + key + "' has the wrong type or is out of range");
  }
}

}  // namespace

// ---------------------------------------------------------------- binary arrays

uint64_t Array::count() const {
  uint64_t n = 1;
  for (uint64_t d : dims) n *= d;
  return n;
}

uint64_t fnv1a64(const char* data, size_t n) {
  return nn::fnv1a64(reinterpret_cast<const uint8_t*>(data), n);  // the checkpoints' checksum
}

void write_array(const std::string& path, const Array& a) {
  if (a.bytes.size() != a.count() * dtype_size(a.dtype))
    gdsr::fail("dataset", std::string(path) + ": payload size does not match the shape");
  std::string s;
  s.reserve(a.bytes.size() + 64);
  s.append(kMagic, 8);
  put(s, static_cast<uint32_t>(a.dtype));
  put(s, static_cast<uint32_t>(a.dims.size()));
  for (uint64_t d : a.dims) put(s, d);
  s += a.bytes;
  put(s, fnv1a64(a.bytes.data(), a.bytes.size()));
  write_file_atomic(path, s);
}

Array read_array(const std::string& path, bool verify_checksum) {
  std::ifstream in(path, std::ios::binary);
  if (!in || fs::is_directory(path)) fail_to_open(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_array(ss.str(), path, verify_checksum);
}

Array parse_array(const std::string& s, const std::string& path, bool verify_checksum) {
  size_t pos = 0;
  auto take = [&](void* dst, size_t n) {
    if (pos + n > s.size()) gdsr::fail("dataset", std::string(path) + ": truncated file");
    std::memcpy(dst, s.data() + pos, n);
    pos += n;
  };
  char magic[8];
  take(magic, 8);
  if (std::memcmp(magic, kMagic, 8) != 0) gdsr::fail("dataset", std::string(path) + ": not a gdsr array (bad magic)");
  uint32_t dtype = 0, ndim = 0;
  take(&dtype, 4);
  take(&ndim, 4);
  if (dtype < 1 || dtype > 3)
    gdsr::fail("dataset", std::string(path) + ": unknown element type " + std::to_string(dtype));
  if (ndim > 8) gdsr::fail("dataset", std::string(path) + ": too many dimensions");
  Array a;
  a.dtype = static_cast<DType>(dtype);
  a.dims.resize(ndim);
  for (auto& d : a.dims) take(&d, 8);
  // The element count, checked against the file size on the way: a product of dimensions
  // that overflows 64 bits must not wrap to a small number that matches.
  uint64_t elems = 1;
  for (uint64_t d : a.dims) {
    // Counts index int32 arrays: no dimension of a gdsr array exceeds 2^31 - 1 (and a huge
    // one beside a zero one would pass the size check with no payload at all).
    if (d > static_cast<uint64_t>(std::numeric_limits<int32_t>::max()))
      gdsr::fail("dataset", std::string(path) + ": dimensions larger than the file (" + std::to_string(d) +
                                ": corrupt header)");
    if (d != 0 && elems > s.size() / d)
      gdsr::fail("dataset", std::string(path) + ": dimensions larger than the file (truncated or corrupt header)");
    elems *= d;
  }
  const uint64_t nbytes = elems * dtype_size(a.dtype);
  if (pos + nbytes + 8 != s.size())
    gdsr::fail("dataset", std::string(path) + ": size " + std::to_string(s.size()) +
                              " bytes does not match its header (truncated or corrupt)");
  a.bytes = s.substr(pos, nbytes);
  pos += nbytes;
  uint64_t sum = 0;
  take(&sum, 8);
  if (verify_checksum && sum != fnv1a64(a.bytes.data(), a.bytes.size()))
    gdsr::fail("dataset", std::string(path) + ": checksum mismatch (corrupt file)");
  return a;
}

Array frames_to_array(const std::vector<Points3>& frames) {
  const uint64_t T = frames.size(), N = frames.empty() ? 0 : static_cast<uint64_t>(frames[0].rows());
  std::vector<float> buf(T * N * 3);
  for (uint64_t t = 0; t < T; ++t) {
    if (static_cast<uint64_t>(frames[t].rows()) != N)
      gdsr::fail("dataset", "frames_to_array: frame " + std::to_string(t) + " has a different vertex count");
    for (uint64_t i = 0; i < N * 3; ++i) buf[t * N * 3 + i] = static_cast<float>(frames[t].data()[i]);
  }
  return make_array(DType::f32, {T, N, 3}, buf.data());
}

std::vector<Points3> array_to_frames(const Array& a, const std::string& what) {
  if (a.dtype != DType::f32 || a.dims.size() != 3 || a.dims[2] != 3)
    gdsr::fail("dataset", std::string(what) + ": expected a float32 T x N x 3 array");
  const uint64_t T = a.dims[0], N = a.dims[1];
  const float* p = data_of<float>(a);
  std::vector<Points3> out;
  out.reserve(T);
  for (uint64_t t = 0; t < T; ++t) {
    out.emplace_back(static_cast<long>(N), 3);
    for (uint64_t i = 0; i < N * 3; ++i) out[t].data()[i] = p[t * N * 3 + i];
  }
  return out;
}

// ---------------------------------------------------------------- validation

void check_uv_layout(const GarmentMesh& g, const std::string& what) {
  if (g.UV.rows() == 0) gdsr::fail("dataset", std::string(what) + ": no UV coordinates");
  if (!g.UV.allFinite()) gdsr::fail("dataset", std::string(what) + ": NaN or infinite UV coordinate");
  if (g.FUV.minCoeff() < 0 || g.FUV.maxCoeff() >= g.UV.rows())
    gdsr::fail("dataset", std::string(what) + ": UV face index out of range");
  for (int f = 0; f < g.FUV.rows(); ++f) {
    const Vec2 a = g.UV.row(g.FUV(f, 0)).transpose(), b = g.UV.row(g.FUV(f, 1)).transpose(),
               c = g.UV.row(g.FUV(f, 2)).transpose();
    const Vec2 e1 = b - a, e2 = c - a;
    const double area2 = std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    const double longest2 = std::max({e1.squaredNorm(), e2.squaredNorm(), (c - b).squaredNorm()});
    if (!(area2 > 1e-8 * longest2) || longest2 == 0)
      gdsr::fail("dataset",
                 std::string(what) + ": degenerate UV triangle " + std::to_string(f) + " (zero area or collinear UVs)");
  }
}

void update_manifest_counts(Dataset& d) {
  DatasetManifest& m = d.manifest;
  m.lr_vertices = static_cast<int>(d.lr.V.rows());
  m.lr_faces = static_cast<int>(d.lr.F.rows());
  m.lr_uv_vertices = static_cast<int>(d.lr.UV.rows());
  m.hr_vertices = static_cast<int>(d.hr.V.rows());
  m.hr_faces = static_cast<int>(d.hr.F.rows());
  m.hr_uv_vertices = static_cast<int>(d.hr.UV.rows());
  m.frames = static_cast<int>(d.lr_frames.size());
  m.layers = std::max(d.lr.num_layers(), d.hr.num_layers());
  m.body_vertices = d.body_frames.empty() ? 0 : static_cast<int>(d.body_frames[0].rows());
  m.body_faces = d.body_frames.empty() ? 0 : static_cast<int>(d.body_faces.rows());
}

void validate_dataset(const Dataset& d, const std::string& where) {
  const DatasetManifest& m = d.manifest;
  if (m.version != kDatasetVersion)
    gdsr::fail("dataset", std::string(where) + ": unsupported version " + std::to_string(m.version));
  if (!(m.fps > 0)) gdsr::fail("dataset", std::string(where) + ": fps must be positive");
  check_garment(d.lr, where + " LR mesh");
  check_garment(d.hr, where + " HR mesh");
  auto count = [&](long have, int want, const std::string& what) {
    if (have != want)
      gdsr::fail("dataset", std::string(where) + ": " + what + " has " + std::to_string(have) + ", manifest says " +
                                std::to_string(want) + " (vertex count mismatch)");
  };
  count(d.lr.V.rows(), m.lr_vertices, "LR mesh vertices");
  count(d.hr.V.rows(), m.hr_vertices, "HR mesh vertices");
  count(d.lr.F.rows(), m.lr_faces, "LR mesh faces");
  count(d.hr.F.rows(), m.hr_faces, "HR mesh faces");
  if (!d.lr_frames.empty() || !d.hr_frames.empty()) {
    check_frames(d.lr_frames, m.lr_vertices, m.frames, where + " LR frames");
    check_frames(d.hr_frames, m.hr_vertices, m.frames, where + " HR frames");
    if (m.body_vertices > 0) check_frames(d.body_frames, m.body_vertices, m.frames, where + " body frames");
  }
  if (m.body_vertices > 0) {
    count(d.body_faces.rows(), m.body_faces, "body faces");
    if (d.body_faces.rows() == 0 || d.body_faces.minCoeff() < 0 || d.body_faces.maxCoeff() >= m.body_vertices)
      gdsr::fail("dataset", std::string(where) + ": body face index out of range");
  }
  validate_correspondence(d.corr);
  if (d.corr.lr_vertices != m.lr_vertices || d.corr.hr_vertices != m.hr_vertices)
    gdsr::fail("dataset", std::string(where) + ": correspondence vertex counts do not match the meshes");
  const UVRaster& r = d.raster;
  if (r.width <= 0 || r.height <= 0 || r.tri.size() != static_cast<size_t>(r.width) * r.height ||
      r.bary.size() != r.tri.size() * 3 || !(r.scale > 0))
    gdsr::fail("dataset", std::string(where) + ": malformed UV raster");
  for (int t : r.tri)
    if (t < -1 || t >= m.hr_faces) gdsr::fail("dataset", std::string(where) + ": UV raster triangle id out of range");
}

// ---------------------------------------------------------------- manifest

DatasetManifest read_manifest(const std::string& path) {
  std::ifstream in(path);
  if (!in || fs::is_directory(path)) fail_to_open(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_manifest(ss.str(), path);
}

DatasetManifest parse_manifest(const std::string& text, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    gdsr::fail("dataset", std::string(path) + ": invalid JSON");
  }
  DatasetManifest m;
  m.version = get<int>(j, "version", path);
  if (m.version != kDatasetVersion)
    gdsr::fail("dataset", std::string(path) + ": unsupported version " + std::to_string(m.version));
  m.garment = get<std::string>(j, "garment", path);
  m.source_motion = get<std::string>(j, "source_motion", path);
  m.layers = get<int>(j, "layers", path);
  m.lr_particle_distance = get<double>(j, "particle_distance_m.lr", path);
  m.hr_particle_distance = get<double>(j, "particle_distance_m.hr", path);
  m.fps = get<double>(j, "fps", path);
  m.frames = get<int>(j, "frames", path);
  m.rest_blend_frames = get<int>(j, "rest_blend_frames", path);
  m.lr_vertices = get<int>(j, "lr.vertices", path);
  m.lr_faces = get<int>(j, "lr.faces", path);
  m.lr_uv_vertices = get<int>(j, "lr.uv_vertices", path);
  m.hr_vertices = get<int>(j, "hr.vertices", path);
  m.hr_faces = get<int>(j, "hr.faces", path);
  m.hr_uv_vertices = get<int>(j, "hr.uv_vertices", path);
  m.body_vertices = get<int>(j, "body.vertices", path);
  m.body_faces = get<int>(j, "body.faces", path);
  if (j.contains("sim_params")) m.sim_params = j["sim_params"];
  if (j.contains("stats")) m.stats = j["stats"];
  if (j.contains("validity")) {
    if (!j["validity"].is_object()) gdsr::fail("dataset", path + ": key 'validity' is not an object");
    m.validity = j["validity"];
  }
  if (m.frames < 0 || m.lr_vertices < 0 || m.hr_vertices < 0 || m.body_vertices < 0)
    gdsr::fail("dataset", path + ": negative count");
  if (!(m.fps > 0 && m.fps <= 1e4)) gdsr::fail("dataset", path + ": fps must be in (0, 10000]");
  return m;
}

// ---------------------------------------------------------------- write / load

namespace {

fs::path absolute_out(const std::string& dir) {
  if (dir.empty()) gdsr::fail("--out", "empty output folder name");
  fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // "DIR/" names DIR
  if (dir.empty() || p.filename().empty() || p.filename() == "." || p.filename() == "..")
    gdsr::fail("--out", "bad output folder '" + dir + "'");
  return p;
}

std::string pid_suffix() { return std::to_string(static_cast<long>(::getpid())); }

}  // namespace

void check_dataset_out(const std::string& dir) {
  const fs::path out = absolute_out(dir);
  const std::string name = out.filename().string();
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(out, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(fs::status(out, ec)))
      gdsr::fail("--out", dir + " exists and is not a folder; refusing to replace it");
    if (!fs::exists(out / "manifest.json", ec))
      gdsr::fail("--out", dir + " exists and is not a gdsr dataset (no manifest.json); refusing to replace it");
    return;
  }
  // A replace killed between its two renames leaves DIR.old.<pid> and no DIR: put it back.
  // The nearest existing ancestor must be a folder we may write in.
  fs::path parent = out.parent_path();
  fs::path anc = parent;
  while (!anc.empty() && !fs::exists(fs::symlink_status(anc, ec)) && anc != anc.parent_path()) anc = anc.parent_path();
  if (!fs::is_directory(anc, ec)) gdsr::fail("--out", dir + ": " + anc.string() + " is not a folder");
  if (::access(anc.c_str(), W_OK) != 0)
    gdsr::fail("--out", dir + ": cannot write in " + anc.string() + ": " + std::strerror(errno));
  if (!fs::is_directory(parent, ec)) return;
  const std::string prefix = name + ".old.";
  for (const auto& e : fs::directory_iterator(parent, ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind(prefix, 0) != 0 || !fs::exists(e.path() / "manifest.json")) continue;
    fs::rename(e.path(), out, ec);
    if (ec)
      gdsr::fail("--out", "found " + e.path().string() + " from an interrupted replace of " + dir +
                              " and cannot restore it: " + ec.message());
    std::fprintf(stderr, "gdsr: note: restored %s from %s (an earlier replace was interrupted)\n", dir.c_str(),
                 e.path().string().c_str());
    return;
  }
}

void write_dataset(const std::string& dir, const Dataset& d) {
  validate_dataset(d, dir);
  check_dataset_out(dir);
  const fs::path final_dir = absolute_out(dir);
  const std::string name = final_dir.filename().string();
  const fs::path tmp = final_dir.parent_path() / (name + ".tmp." + pid_suffix());
  std::error_code ec;
  remove_stale_temps(final_dir.parent_path().string(), {name});  // from killed writes
  fs::remove_all(tmp, ec);
  fs::create_directories(tmp, ec);
  if (ec) gdsr::fail("dataset", "cannot create " + tmp.string() + ": " + ec.message());
  const std::string t = tmp.string();
  // A failed write (full disk, ...) takes its temp folder with it.
  struct RemoveOnFailure {
    const fs::path& dir;
    bool done = false;
    ~RemoveOnFailure() {
      std::error_code e;
      if (!done) fs::remove_all(dir, e);
    }
  } cleanup{tmp};

  write_file_atomic(join(t, "manifest.json"), manifest_json(d.manifest, d.raster).dump(2) + "\n");
  write_obj(join(t, "lr.obj"), d.lr);
  write_obj(join(t, "hr.obj"), d.hr);
  auto layers = [](const GarmentMesh& g) {
    return g.layer.empty() ? std::vector<int>(static_cast<size_t>(g.V.rows()), 0) : g.layer;
  };
  write_array(join(t, "lr_layer.bin"), ints_array(layers(d.lr), {static_cast<uint64_t>(d.lr.V.rows())}));
  write_array(join(t, "hr_layer.bin"), ints_array(layers(d.hr), {static_cast<uint64_t>(d.hr.V.rows())}));
  write_array(join(t, "lr_frames.bin"), frames_to_array(d.lr_frames));
  write_array(join(t, "hr_frames.bin"), frames_to_array(d.hr_frames));
  if (d.has_body()) {
    write_array(join(t, "body_frames.bin"), frames_to_array(d.body_frames));
    write_array(join(t, "body_faces.bin"), faces_array(d.body_faces));
  }
  const Correspondence& c = d.corr;
  write_array(join(t, "corr_hr_from_lr_tri.bin"),
              ints_array(c.hr_from_lr.tri, {static_cast<uint64_t>(c.hr_from_lr.size())}));
  write_array(join(t, "corr_hr_from_lr_bary.bin"), bary_array(c.hr_from_lr));
  write_array(join(t, "corr_lr_from_hr_tri.bin"),
              ints_array(c.lr_from_hr.tri, {static_cast<uint64_t>(c.lr_from_hr.size())}));
  write_array(join(t, "corr_lr_from_hr_bary.bin"), bary_array(c.lr_from_hr));
  write_array(join(t, "corr_hr_nearest_lr.bin"),
              ints_array(c.hr_nearest_lr, {static_cast<uint64_t>(c.hr_nearest_lr.size())}));
  const UVRaster& r = d.raster;
  write_array(join(t, "uv_raster_tri.bin"),
              ints_array(r.tri, {static_cast<uint64_t>(r.height), static_cast<uint64_t>(r.width)}));
  write_array(
      join(t, "uv_raster_bary.bin"),
      make_array(DType::f32, {static_cast<uint64_t>(r.height), static_cast<uint64_t>(r.width), 3}, r.bary.data()));

  // Swap in: an existing dataset is moved aside first, removed after the rename succeeds.
  const fs::path old = final_dir.parent_path() / (name + ".old." + pid_suffix());
  fs::remove_all(old, ec);
  const bool had = fs::exists(final_dir);
  if (had) {
    fs::rename(final_dir, old, ec);
    if (ec) gdsr::fail("dataset", "cannot move the existing " + final_dir.string() + " aside: " + ec.message());
  }
  fs::rename(tmp, final_dir, ec);
  if (ec) {
    const std::string why = ec.message();
    if (had) fs::rename(old, final_dir, ec);  // put the old dataset back
    gdsr::fail("dataset", "cannot rename " + tmp.string() + " to " + final_dir.string() + ": " + why);
  }
  cleanup.done = true;
  if (had) fs::remove_all(old, ec);
}

Dataset load_dataset(const std::string& dir, const LoadOptions& opt) {
  if (!fs::is_directory(dir)) gdsr::fail("dataset", "no dataset folder " + dir);
  Dataset d;
  const std::string mpath = join(dir, "manifest.json");
  d.manifest = read_manifest(mpath);
  const DatasetManifest& m = d.manifest;
  const bool v = opt.verify_checksums;

  for (const char* name : {"lr.obj", "hr.obj"})
    if (!fs::exists(join(dir, name))) gdsr::fail("dataset", "missing file " + join(dir, name));
  d.lr = read_obj_garment(join(dir, "lr.obj"));
  d.hr = read_obj_garment(join(dir, "hr.obj"));
  auto read_layer = [&](GarmentMesh& g, const std::string& name) {
    const Array a = read_array(join(dir, name), v);
    expect_shape(a, DType::i32, {static_cast<uint64_t>(g.V.rows())}, join(dir, name));
    g.layer = to_ints(a);
    for (int l : g.layer) {
      if (l < 0) gdsr::fail("dataset", join(dir, name) + ": negative layer id");
      // Layer ids count the cloth layers (a handful); a huge one would make every per-layer
      // loop run for ever.
      if (l >= kMaxLayers)
        gdsr::fail("dataset", join(dir, name) + ": layer id " + std::to_string(l) + " out of range (at most " +
                                  std::to_string(kMaxLayers) + " layers)");
    }
  };
  read_layer(d.lr, "lr_layer.bin");
  read_layer(d.hr, "hr_layer.bin");

  if (opt.frames) {
    d.lr_frames = read_frames(join(dir, "lr_frames.bin"), v);
    d.hr_frames = read_frames(join(dir, "hr_frames.bin"), v);
  }
  if (m.body_vertices > 0) {
    if (opt.frames) d.body_frames = read_frames(join(dir, "body_frames.bin"), v);
    const Array bf = read_array(join(dir, "body_faces.bin"), v);
    expect_shape(bf, DType::i32, {static_cast<uint64_t>(m.body_faces), 3}, join(dir, "body_faces.bin"));
    d.body_faces = array_faces(bf);
  }

  Correspondence& c = d.corr;
  c.lr_F = d.lr.F;
  c.hr_F = d.hr.F;
  c.lr_uv_to_vertex = d.lr.uv_to_vertex;
  c.lr_vertices = static_cast<int>(d.lr.V.rows());
  c.hr_vertices = static_cast<int>(d.hr.V.rows());
  c.hr_from_lr = read_bary(dir, "corr_hr_from_lr", c.hr_vertices, static_cast<int>(c.lr_F.rows()), v);
  c.lr_from_hr =
      read_bary(dir, "corr_lr_from_hr", static_cast<int>(d.lr.UV.rows()), static_cast<int>(c.hr_F.rows()), v);
  const Array nl = read_array(join(dir, "corr_hr_nearest_lr.bin"), v);
  expect_shape(nl, DType::i32, {static_cast<uint64_t>(c.hr_vertices)}, join(dir, "corr_hr_nearest_lr.bin"));
  c.hr_nearest_lr = to_ints(nl);
  check_index_range(c.hr_nearest_lr, 0, c.lr_vertices, join(dir, "corr_hr_nearest_lr.bin"), "LR vertex");

  nlohmann::json j;
  std::ifstream(mpath) >> j;
  UVRaster& r = d.raster;
  r.width = get<int>(j, "uv_raster.width", mpath);
  r.height = get<int>(j, "uv_raster.height", mpath);
  r.scale = get<double>(j, "uv_raster.scale", mpath);
  r.u0 = get<double>(j, "uv_raster.u0", mpath);
  r.v0 = get<double>(j, "uv_raster.v0", mpath);
  const Array rt = read_array(join(dir, "uv_raster_tri.bin"), v);
  expect_shape(rt, DType::i32, {static_cast<uint64_t>(r.height), static_cast<uint64_t>(r.width)},
               join(dir, "uv_raster_tri.bin"));
  r.tri = to_ints(rt);
  check_index_range(r.tri, -1, static_cast<int>(d.hr.F.rows()), join(dir, "uv_raster_tri.bin"), "HR triangle");
  const Array rb = read_array(join(dir, "uv_raster_bary.bin"), v);
  expect_shape(rb, DType::f32, {static_cast<uint64_t>(r.height), static_cast<uint64_t>(r.width), 3},
               join(dir, "uv_raster_bary.bin"));
  r.bary.assign(data_of<float>(rb), data_of<float>(rb) + rb.count());
  for (size_t px = 0; px < r.tri.size(); ++px)  // float32: the weights sum to 1 within rounding
    if (r.tri[px] >= 0)
      check_bary_row(r.bary[3 * px], r.bary[3 * px + 1], r.bary[3 * px + 2], 1e-4, join(dir, "uv_raster_bary.bin"), px);

  validate_dataset(d, dir);
  return d;
}

}  // namespace gdsr

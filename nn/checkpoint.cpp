#include "nn/checkpoint.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include <fcntl.h>
#include <unistd.h>

namespace nn {

namespace {

constexpr char kMagic[8] = {'G', 'D', 'S', 'R', 'C', 'K', 'P', 'T'};
constexpr size_t kHeader = 8 + 4 + 4 + 8 + 8;

size_t dtype_size(DType d) {
  switch (d) {
    case DType::F32:
      return 4;
    case DType::F64:
      return 8;
    case DType::C64:
      return 8;
    case DType::C128:
      return 16;
    case DType::I64:
      return 8;
  }
  return 0;
}

struct Writer {
  std::vector<uint8_t> buf;
  void raw(const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    buf.insert(buf.end(), b, b + n);
  }
  template <class V> void pod(V v) { raw(&v, sizeof v); }
  void str(const std::string& s) {
    pod<uint64_t>(s.size());
    raw(s.data(), s.size());
  }
};

struct Reader {
  const uint8_t* p;
  size_t n, pos = 0;
  const std::string& path;
  void need(size_t k) {
    if (k > n - pos) throw ag::Error("checkpoint '" + path + "': payload ends early (corrupted)");
  }
  void raw(void* dst, size_t k) {
    need(k);
    std::memcpy(dst, p + pos, k);
    pos += k;
  }
  template <class V> V pod() {
    V v;
    raw(&v, sizeof v);
    return v;
  }
  std::string str() {
    const uint64_t len = pod<uint64_t>();
    need(len);
    std::string s(reinterpret_cast<const char*>(p + pos), len);
    pos += len;
    return s;
  }
};

}  // namespace

std::string dtype_name(DType d) {
  switch (d) {
    case DType::F32:
      return "float32";
    case DType::F64:
      return "float64";
    case DType::C64:
      return "complex64";
    case DType::C128:
      return "complex128";
    case DType::I64:
      return "int64";
  }
  return "unknown";
}

uint64_t fnv1a64(const uint8_t* data, size_t n) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (size_t i = 0; i < n; ++i) {
    h ^= data[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

const CheckpointEntry* Checkpoint::find(const std::string& name) const {
  for (const auto& e : entries)
    if (e.name == name) return &e;
  return nullptr;
}

const CheckpointEntry& Checkpoint::get(const std::string& name, DType d) const {
  const CheckpointEntry* e = find(name);
  if (!e) throw ag::Error("checkpoint: no entry '" + name + "'");
  if (e->dtype != d)
    throw ag::Error("checkpoint: entry '" + name + "' is " + dtype_name(e->dtype) + ", expected " + dtype_name(d));
  return *e;
}

void Checkpoint::add_raw(const std::string& name, DType d, const ag::Shape& shape, const void* data, int64_t n) {
  if (find(name)) throw ag::Error("checkpoint: duplicate entry '" + name + "'");
  if (ag::numel_of(shape) != n)
    throw ag::Error("checkpoint: entry '" + name + "' has " + std::to_string(n) + " values for shape " +
                    ag::shape_str(shape));
  if (shape.size() > 255) throw ag::Error("checkpoint: entry '" + name + "' has too many dimensions");
  CheckpointEntry e;
  e.name = name;
  e.dtype = d;
  e.shape = shape;
  const auto* b = static_cast<const uint8_t*>(data);
  e.bytes.assign(b, b + static_cast<size_t>(n) * dtype_size(d));
  entries.push_back(std::move(e));
}

void Checkpoint::read_raw(const std::string& name, DType d, const ag::Shape& shape, void* data, int64_t n) const {
  const CheckpointEntry& e = get(name, d);
  if (e.shape != shape)
    throw ag::Error("checkpoint: entry '" + name + "' has shape " + ag::shape_str(e.shape) + ", expected " +
                    ag::shape_str(shape));
  if (e.bytes.size() != static_cast<size_t>(n) * dtype_size(d))
    throw ag::Error("checkpoint: entry '" + name + "' has the wrong byte count");
  if (!e.bytes.empty()) std::memcpy(data, e.bytes.data(), e.bytes.size());
}

void write_checkpoint(const std::string& path, const Checkpoint& ck) {
  Writer pl;
  pl.pod<int64_t>(ck.step);
  pl.str(ck.metadata);
  pl.pod<uint64_t>(ck.entries.size());
  for (const auto& e : ck.entries) {
    pl.str(e.name);
    pl.pod<uint8_t>(static_cast<uint8_t>(e.dtype));
    pl.pod<uint8_t>(static_cast<uint8_t>(e.shape.size()));
    for (int64_t d : e.shape) pl.pod<int64_t>(d);
    pl.pod<uint64_t>(e.bytes.size());
    pl.raw(e.bytes.data(), e.bytes.size());
  }
  Writer hd;
  hd.raw(kMagic, 8);
  hd.pod<uint32_t>(Checkpoint::kVersion);
  hd.pod<uint32_t>(0);
  hd.pod<uint64_t>(pl.buf.size());
  hd.pod<uint64_t>(fnv1a64(pl.buf.data(), pl.buf.size()));

  // Temp file, fsync, rename, fsync of the folder: after a crash or power loss the final
  // name holds either the previous file or the complete new one.
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw ag::Error("checkpoint '" + path + "': cannot open '" + tmp + "' for writing");
  auto write_all = [fd](const std::vector<uint8_t>& b) {
    size_t done = 0;
    while (done < b.size()) {
      const ssize_t k = ::write(fd, b.data() + done, b.size() - done);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) return false;
      done += static_cast<size_t>(k);
    }
    return true;
  };
  const bool ok = write_all(hd.buf) && write_all(pl.buf) && ::fsync(fd) == 0;
  if (::close(fd) != 0 || !ok) {
    std::remove(tmp.c_str());
    throw ag::Error("checkpoint '" + path + "': write failed (disk full?)");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw ag::Error("checkpoint '" + path + "': cannot rename the temporary file into place");
  }
  std::string dir = path.substr(0, path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/'));
  if (dir.empty()) dir = path.find('/') == 0 ? "/" : ".";
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);  // best effort: some file systems refuse fsync on a folder
    ::close(dfd);
  }
}

Checkpoint read_checkpoint(const std::string& path) {
  {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      throw ag::Error("checkpoint '" + path + "': is a folder, not a checkpoint file");
  }
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  if (!f) {
    const int err = errno;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw ag::Error("checkpoint '" + path + "': no such file");
    throw ag::Error("checkpoint '" + path + "': cannot open for reading: " + std::strerror(err ? err : EACCES));
  }
  const std::streamoff size = f.tellg();
  if (size < 0) throw ag::Error("checkpoint '" + path + "': cannot determine the file size");
  f.seekg(0);
  std::vector<uint8_t> all(static_cast<size_t>(size));
  if (size > 0) f.read(reinterpret_cast<char*>(all.data()), size);
  if (!f) throw ag::Error("checkpoint '" + path + "': read failed");
  return parse_checkpoint(all, path);
}

Checkpoint parse_checkpoint(const std::vector<uint8_t>& all, const std::string& path) {
  if (all.size() < kHeader)
    throw ag::Error("checkpoint '" + path + "': truncated (" + std::to_string(all.size()) + " bytes, header alone is " +
                    std::to_string(kHeader) + ")");
  if (std::memcmp(all.data(), kMagic, 8) != 0)
    throw ag::Error("checkpoint '" + path + "': not a gdsr checkpoint (bad magic)");
  uint32_t version;
  uint64_t payload_size, checksum;
  std::memcpy(&version, all.data() + 8, 4);
  std::memcpy(&payload_size, all.data() + 16, 8);
  std::memcpy(&checksum, all.data() + 24, 8);
  if (version != Checkpoint::kVersion)
    throw ag::Error("checkpoint '" + path + "': format version " + std::to_string(version) + ", this build reads " +
                    std::to_string(Checkpoint::kVersion));
  const uint64_t have = all.size() - kHeader;
  if (have < payload_size)
    throw ag::Error("checkpoint '" + path + "': truncated (payload " + std::to_string(have) + " of " +
                    std::to_string(payload_size) + " bytes)");
  if (have > payload_size)
    throw ag::Error("checkpoint '" + path + "': " + std::to_string(have - payload_size) +
                    " trailing bytes (corrupted)");
  const uint8_t* pl = all.data() + kHeader;
  if (fnv1a64(pl, payload_size) != checksum)
    throw ag::Error("checkpoint '" + path + "': checksum mismatch (corrupted)");

  Checkpoint ck;
  Reader r{pl, static_cast<size_t>(payload_size), 0, path};
  ck.step = r.pod<int64_t>();
  ck.metadata = r.str();
  const uint64_t count = r.pod<uint64_t>();
  for (uint64_t i = 0; i < count; ++i) {
    CheckpointEntry e;
    e.name = r.str();
    const uint8_t dt = r.pod<uint8_t>();
    if (dt < 1 || dt > 5) throw ag::Error("checkpoint '" + path + "': entry '" + e.name + "' has an unknown dtype");
    e.dtype = static_cast<DType>(dt);
    const uint8_t nd = r.pod<uint8_t>();
    // The element count, checked against the payload on the way (no signed overflow for
    // a corrupt shape).
    uint64_t numel = 1;
    for (uint8_t k = 0; k < nd; ++k) {
      const int64_t d = r.pod<int64_t>();
      if (d < 0 || (d > 0 && numel > payload_size / static_cast<uint64_t>(d)))
        throw ag::Error("checkpoint '" + path + "': entry '" + e.name + "' has a corrupt shape");
      numel *= static_cast<uint64_t>(d);
      e.shape.push_back(d);
    }
    const uint64_t nb = r.pod<uint64_t>();
    if (nb != numel * dtype_size(e.dtype))
      throw ag::Error("checkpoint '" + path + "': entry '" + e.name + "' size does not match its shape");
    r.need(nb);
    e.bytes.assign(pl + r.pos, pl + r.pos + nb);
    r.pos += nb;
    if (ck.find(e.name)) throw ag::Error("checkpoint '" + path + "': duplicate entry '" + e.name + "'");
    ck.entries.push_back(std::move(e));
  }
  if (r.pos != r.n) throw ag::Error("checkpoint '" + path + "': unexpected bytes after the last entry");
  return ck;
}

template <class T> void save_checkpoint(const std::string& path, const Module<T>& model, const AdamW<T>* opt,
                                        int64_t step, const std::string& metadata_json) {
  Checkpoint ck;
  ck.step = step;
  ck.metadata = metadata_json;
  for (const auto& [name, t] : model.named_parameters()) ck.add("param/" + name, t);
  if (opt) {
    const AdamWOptions& o = opt->options();
    ck.add<double>("adamw/#options", {6}, {o.lr, o.beta1, o.beta2, o.eps, o.weight_decay, o.amsgrad ? 1.0 : 0.0});
    ck.add<int64_t>("adamw/#steps", {1}, {opt->steps_taken()});
    for (const auto& s : opt->slots()) {
      const std::string p = "adamw/" + s.name + "/";
      ck.add<int64_t>(p + "step", {1}, {s.step});
      ck.add<T>(p + "m", {static_cast<int64_t>(s.m.size())}, s.m);
      ck.add<T>(p + "v", {static_cast<int64_t>(s.v.size())}, s.v);
      ck.add<T>(p + "vmax", {static_cast<int64_t>(s.vmax.size())}, s.vmax);
    }
  }
  write_checkpoint(path, ck);
}

template <class T> Checkpoint load_checkpoint(const std::string& path, Module<T>& model, AdamW<T>* opt) {
  Checkpoint ck = read_checkpoint(path);
  const std::string where = "checkpoint '" + path + "': ";
  // Check everything before touching the model, so a refused file leaves it unchanged.
  auto params = model.named_parameters();
  std::set<std::string> expected;
  for (auto& [name, t] : params) {
    const std::string key = "param/" + name;
    expected.insert(key);
    const CheckpointEntry* e = ck.find(key);
    if (!e) throw ag::Error(where + "parameter '" + name + "' is missing");
    if (e->dtype != Checkpoint::dtype_of<T>())
      throw ag::Error(where + "parameter '" + name + "' is " + dtype_name(e->dtype) + ", the model uses " +
                      dtype_name(Checkpoint::dtype_of<T>()));
    if (e->shape != t.shape())
      throw ag::Error(where + "parameter '" + name + "' has shape " + ag::shape_str(e->shape) + ", the model has " +
                      ag::shape_str(t.shape()));
  }
  for (const auto& e : ck.entries)
    if (e.name.rfind("param/", 0) == 0 && !expected.count(e.name))
      throw ag::Error(where + "parameter '" + e.name.substr(6) + "' is not in the model");
  std::vector<double> options;  // lr, beta1, beta2, eps, weight_decay, amsgrad
  if (opt) {
    if (!ck.find("adamw/#options")) throw ag::Error(where + "holds no optimizer state");
    options = ck.read<double>("adamw/#options");
    if (options.empty()) throw ag::Error(where + "the optimizer options are empty");
    AdamWOptions with_lr = opt->options();
    with_lr.lr = options[0];
    try {
      check_adamw_options(with_lr);
    } catch (const ag::Error& e) {
      throw ag::Error(where + e.what());
    }
    std::set<std::string> slots;
    for (const auto& s : opt->slots()) {
      slots.insert(s.name);
      for (const char* k : {"step", "m", "v", "vmax"})
        if (!ck.find("adamw/" + s.name + "/" + k))
          throw ag::Error(where + "optimizer state '" + s.name + "/" + k + "' is missing");
      for (const char* k : {"m", "v", "vmax"}) {
        const auto* e = ck.find("adamw/" + s.name + "/" + k);
        const uint64_t n = e->bytes.size() / sizeof(T);
        if (e->dtype != Checkpoint::dtype_of<T>() || (n != 0 && n != static_cast<uint64_t>(s.reals())))
          throw ag::Error(where + "optimizer state '" + s.name + "/" + k + "' does not fit the parameter");
      }
    }
    for (const auto& e : ck.entries) {
      if (e.name.rfind("adamw/", 0) != 0 || e.name[6] == '#') continue;
      const std::string slot = e.name.substr(6, e.name.rfind('/') - 6);
      if (!slots.count(slot)) throw ag::Error(where + "optimizer slot '" + slot + "' is not in the optimizer");
    }
  }
  for (auto& [name, t] : params) ck.read_into("param/" + name, t);
  if (opt) {
    opt->set_lr(options[0]);
    opt->set_steps_taken(ck.read<int64_t>("adamw/#steps").at(0));
    for (auto& s : opt->slots()) {
      const std::string p = "adamw/" + s.name + "/";
      s.step = ck.read<int64_t>(p + "step").at(0);
      s.m = ck.read<T>(p + "m");
      s.v = ck.read<T>(p + "v");
      s.vmax = ck.read<T>(p + "vmax");
    }
  }
  return ck;
}

template void save_checkpoint(const std::string&, const Module<float>&, const AdamW<float>*, int64_t,
                              const std::string&);
template void save_checkpoint(const std::string&, const Module<double>&, const AdamW<double>*, int64_t,
                              const std::string&);
template Checkpoint load_checkpoint(const std::string&, Module<float>&, AdamW<float>*);
template Checkpoint load_checkpoint(const std::string&, Module<double>&, AdamW<double>*);

}  // namespace nn

// The readers the fuzzers drive, one entry point each, fed the bytes of one file: the same
// functions the command line reaches when it reads an OBJ, a dataset array or manifest, a
// checkpoint or a config. A clean refusal is a gdsr::Error or ag::Error; anything else (another
// exception, a crash, a hang, a huge allocation) is a bug. Used by the libFuzzer programs
// (fuzz/fuzz_main.cpp, cmake -DGDSR_FUZZ=ON) and by the regression test that replays the
// kept inputs in tests/fuzz_corpus/<target>/ (tests/fuzz/).
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/data/dataset.hpp"
#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/model/model_checkpoint.hpp"
#include "gdsr/model/model_config.hpp"
#include "nn/checkpoint.hpp"
#include "train/loss_config.hpp"

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace gdsr_fuzz {

inline void obj(const std::string& b) {
  const gdsr::ObjData d = gdsr::parse_obj(b, "fuzz.obj");
  if (d.has_uv()) gdsr::garment_from_obj(d, "fuzz.obj");
}

// A dataset array: the header, the size and checksum checks, then frames as the loader
// takes them. The checksum (the last 8 bytes) is recomputed over the payload the header
// describes, when the file is long enough to hold one.
inline void array(std::string b) {
  if (b.size() >= 24) {
    uint32_t ndim = 0;
    std::memcpy(&ndim, b.data() + 12, 4);
    const size_t start = 16 + 8 * static_cast<size_t>(ndim);
    if (ndim <= 8 && start + 8 <= b.size()) {
      const uint64_t sum = gdsr::fnv1a64(b.data() + start, b.size() - 8 - start);
      std::memcpy(&b[b.size() - 8], &sum, 8);
    }
  }
  const gdsr::Array a = gdsr::parse_array(b, "fuzz.bin");
  if (a.dtype == gdsr::DType::f32 && a.dims.size() == 3 && a.dims[2] == 3) gdsr::array_to_frames(a, "fuzz.bin");
}

inline void manifest(const std::string& b) { gdsr::parse_manifest(b, "manifest.json"); }

// A checkpoint (header: magic, version, reserved, payload size, checksum; 32 bytes) with its
// checksum recomputed, then the model config in its metadata, as gdsr infer reads it.
inline void checkpoint(const std::string& b) {
  std::vector<uint8_t> v(b.begin(), b.end());
  if (v.size() >= 32) {
    const uint64_t sum = nn::fnv1a64(v.data() + 32, v.size() - 32);
    std::memcpy(v.data() + 24, &sum, 8);
  }
  const nn::Checkpoint ck = nn::parse_checkpoint(v, "fuzz.ckpt");
  gdsr::config_from_checkpoint(ck, "fuzz.ckpt");
}

inline void model_config(const std::string& b) { gdsr::model_config_from_json_text(b, "fuzz.json"); }
inline void loss_config(const std::string& b) { gdsr::loss_config_from_json_text(b, "fuzz.json"); }

struct Target {
  const char* name;  // also the folder of its kept inputs: tests/fuzz_corpus/<name>/
  void (*run)(const std::string& bytes);
};
inline const Target kTargets[] = {{"obj", obj},
                                  {"array", [](const std::string& b) { array(b); }},  // array takes a copy
                                  {"manifest", manifest},
                                  {"checkpoint", checkpoint},
                                  {"model_config", model_config},
                                  {"loss_config", loss_config}};

// True when the input loads, false on a clean refusal; any other exception propagates.
inline bool run_one(const Target& t, const std::string& bytes) {
  try {
    t.run(bytes);
    return true;
  } catch (const gdsr::Error&) {
    return false;
  } catch (const ag::Error&) {
    return false;
  }
}

}  // namespace gdsr_fuzz

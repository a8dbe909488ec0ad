// Checkpoints: named tensors (model parameters and optimizer state), the step count and a
// free-form JSON metadata string in one binary file.
//
// File format, version 1 (little-endian):
//   "GDSRCKPT" (8 bytes) | u32 version | u32 flags (0) | u64 payload size | u64 FNV-1a-64 of
//   the payload | payload
//   payload: i64 step | str metadata | u64 entry count | entries
//   entry:   str name | u8 dtype | u8 ndim | i64 dims[ndim] | u64 byte count | raw values
//   str:     u64 length | bytes
// Files are written to "<path>.tmp" and renamed, so a crash never leaves a half file under
// the final name. Reading refuses wrong magic/version, a size that differs from the header
// (truncation or trailing bytes) and a checksum mismatch, naming the file.
//
// Entry names used by save_checkpoint: "param/<name>" for model parameters,
// "adamw/<name>/{step,m,v,vmax}" per optimizer slot, "adamw/#options" (f64: lr, beta1,
// beta2, eps, weight_decay, amsgrad) and "adamw/#steps" (i64).
#pragma once

#include "autograd/tensor.hpp"
#include "nn/adamw.hpp"
#include "nn/module.hpp"

#include <complex>
#include <cstdint>
#include <string>
#include <vector>

namespace nn {

enum class DType : uint8_t { F32 = 1, F64 = 2, C64 = 3, C128 = 4, I64 = 5 };
std::string dtype_name(DType d);

struct CheckpointEntry {
  std::string name;
  DType dtype = DType::F32;
  ag::Shape shape;
  std::vector<uint8_t> bytes;
};

struct Checkpoint {
  static constexpr uint32_t kVersion = 1;
  int64_t step = 0;
  std::string metadata;  // free-form, JSON by convention
  std::vector<CheckpointEntry> entries;

  const CheckpointEntry* find(const std::string& name) const;  // nullptr if absent
  // Append a tensor / plain values under a new name (throws on a duplicate name).
  template <class S> void add(const std::string& name, const ag::Tensor<S>& t) {
    add_raw(name, dtype_of<S>(), t.shape(), t.data(), t.numel());
  }
  template <class S> void add(const std::string& name, const ag::Shape& shape, const std::vector<S>& v) {
    add_raw(name, dtype_of<S>(), shape, v.data(), static_cast<int64_t>(v.size()));
  }
  // Copy an entry into an existing tensor; throws if absent or dtype/shape differ.
  template <class S> void read_into(const std::string& name, ag::Tensor<S>& t) const {
    read_raw(name, dtype_of<S>(), t.shape(), t.data(), t.numel());
  }
  template <class S> std::vector<S> read(const std::string& name) const {
    const CheckpointEntry& e = get(name, dtype_of<S>());
    std::vector<S> v(e.bytes.size() / sizeof(S));
    read_raw(name, dtype_of<S>(), e.shape, v.data(), static_cast<int64_t>(v.size()));
    return v;
  }

  template <class S> static DType dtype_of();

 private:
  const CheckpointEntry& get(const std::string& name, DType d) const;
  void add_raw(const std::string& name, DType d, const ag::Shape& shape, const void* data, int64_t n);
  void read_raw(const std::string& name, DType d, const ag::Shape& shape, void* data, int64_t n) const;
};

template <> inline DType Checkpoint::dtype_of<float>() { return DType::F32; }
template <> inline DType Checkpoint::dtype_of<double>() { return DType::F64; }
template <> inline DType Checkpoint::dtype_of<std::complex<float>>() { return DType::C64; }
template <> inline DType Checkpoint::dtype_of<std::complex<double>>() { return DType::C128; }
template <> inline DType Checkpoint::dtype_of<int64_t>() { return DType::I64; }

// Low level: whole file <-> Checkpoint.
void write_checkpoint(const std::string& path, const Checkpoint& ck);
Checkpoint read_checkpoint(const std::string& path);
// The same on the file's bytes; `path` names the file in errors.
Checkpoint parse_checkpoint(const std::vector<uint8_t>& bytes, const std::string& path);

// FNV-1a, 64 bit.
uint64_t fnv1a64(const uint8_t* data, size_t n);

// Model parameters (+ optimizer state if opt != nullptr) of a float or double model.
template <class T> void save_checkpoint(const std::string& path, const Module<T>& model, const AdamW<T>* opt,
                                        int64_t step, const std::string& metadata_json = "{}");
// Loads into an existing model (and optimizer). Every model parameter must be in the file
// with the same dtype and shape and the file must hold no other parameters; with opt the
// file must hold the optimizer state of exactly the optimizer's slots. Returns the file
// (step, metadata, all entries).
template <class T> Checkpoint load_checkpoint(const std::string& path, Module<T>& model, AdamW<T>* opt);

}  // namespace nn

// The bad-input corpus (issue #15): one table of bad flags and bad files for every
// subcommand and every file gdsr reads, and one runner. Each case must exit 1 with a single
// "gdsr: error:" line naming the flag or file at fault, leak no C++ internals, and leave the
// corpus folder byte for byte as it was (pre-existing datasets, runs, predictions, exports
// and PNGs included: nothing written, nothing lost, no temp left behind).
#include "tests/support/cli_fixtures.hpp"
#include "tests/support/cli_run.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

using gdsr_test::gdsr_run;
using gdsr_test::Run;
using gdsr_test::slurp;
using gdsr_test::TempDir;
namespace fs = std::filesystem;

namespace {

// Scratch inputs a case corrupts; removed before each case, so every case starts clean.
const char* const kScratch[] = {"bad", "bad.ckpt", "badpred", "badexp", "bad.json"};

// ------------------------------------------------------------ corruptions of one file
void put(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::trunc) << text; }

void cut(const std::string& path, long keep) {  // keep < 0: drop -keep bytes from the end
  const auto size = static_cast<long>(fs::file_size(path));
  fs::resize_file(path, static_cast<uintmax_t>(keep >= 0 ? keep : size + keep));
}

void flip(const std::string& path, long offset) {  // offset < 0: from the end
  std::string s = slurp(path);
  s[static_cast<size_t>(offset >= 0 ? offset : static_cast<long>(s.size()) + offset)] ^= 0x5a;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << s;
}

void replace(const std::string& path, const std::string& from, const std::string& to) {
  std::string s = slurp(path);
  REQUIRE(s.find(from) != std::string::npos);
  s.replace(s.find(from), from.size(), to);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << s;
}

// Sets the JSON value at `pointer` (e.g. "/lr/vertices"); a null value removes the key.
void json_set(const std::string& path, const std::string& pointer, const nlohmann::json& v) {
  nlohmann::json j = nlohmann::json::parse(slurp(path));
  const nlohmann::json::json_pointer p(pointer);
  if (v.is_null())
    j[p.parent_pointer()].erase(p.back());
  else
    j[p] = v;
  std::ofstream(path, std::ios::trunc) << j.dump(1);
}

// Rewrites a dataset array with a valid header and checksum but element `k` (as float32,
// int32 or float64, whichever the file holds) set to `value`.
void set_element(const std::string& path, size_t k, double value) {
  gdsr::Array a = gdsr::read_array(path);
  if (a.dtype == gdsr::DType::f32) {
    const float f = static_cast<float>(value);
    std::memcpy(&a.bytes[k * 4], &f, 4);
  } else if (a.dtype == gdsr::DType::i32) {
    const int32_t i = static_cast<int32_t>(value);
    std::memcpy(&a.bytes[k * 4], &i, 4);
  } else {
    std::memcpy(&a.bytes[k * 8], &value, 8);
  }
  gdsr::write_array(path, a);
}

// An array of the given type and dimensions (payload zero) in place of `path`.
void set_shape(const std::string& path, gdsr::DType t, std::vector<uint64_t> dims) {
  gdsr::Array a;
  a.dtype = t;
  a.dims = std::move(dims);
  a.bytes.assign(a.count() * (t == gdsr::DType::f64 ? 8 : 4), '\0');
  gdsr::write_array(path, a);
}

// ------------------------------------------------------------ the table
using Setup = std::function<void(const TempDir&)>;

struct Case {
  std::string args;    // gdsr arguments; "{d}" is the corpus folder
  std::string needle;  // the flag or file the error line must name
  Setup setup;         // writes the bad input into scratch copies (may be empty)
  std::string prefix;  // shell words before the binary (a full disk)
  Case(std::string a, std::string n, Setup s = {}, std::string p = {})
      : args(std::move(a)), needle(std::move(n)), setup(std::move(s)), prefix(std::move(p)) {}
};

// The shell runs gdsr with files limited to `kb` KiB (ulimit counts 512-byte blocks) and
// SIGXFSZ ignored: a longer write fails with EFBIG, as on a full disk.
std::string full_disk(int kb) { return "trap '' XFSZ; ulimit -f " + std::to_string(2 * kb) + "; "; }

// `from` (a fixture under the corpus folder, or an absolute path) copied to the scratch name
// `to`, then `f` applied to the copy.
Setup on_copy(const std::string& from, const std::string& to, std::function<void(const std::string&)> f) {
  return [=](const TempDir& d) {
    fs::copy(from[0] == '/' ? from : d / from, d / to, fs::copy_options::recursive);
    f(d / to);
  };
}
Setup bad_ds(std::function<void(const std::string&)> f) { return on_copy("ds", "bad", std::move(f)); }
Setup bad_ckpt(std::function<void(const std::string&)> f) {
  return on_copy("run/model.ckpt", "bad.ckpt", std::move(f));
}
Setup bad_pred(std::function<void(const std::string&)> f) { return on_copy("pred", "badpred", std::move(f)); }
Setup bad_exports(std::function<void(const std::string&)> f) { return on_copy("exp_md", "badexp", std::move(f)); }
Setup bad_json(std::function<void(const std::string&)> f) {
  return on_copy(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json", "bad.json", std::move(f));
}
Setup text_json(const std::string& text) {
  return [text](const TempDir& d) { put(d / "bad.json", text); };
}

const std::string kCheck = "data check --data {d}/bad";
const std::string kInfer = "infer --model {d}/run/model.ckpt --out {d}/pred --data ";
const std::string kInferBad = "infer --data {d}/ds --out {d}/pred --model {d}/bad.ckpt";
const std::string kEvalBad = "eval --no-export --data {d}/ds --pred {d}/badpred";
const std::string kTrainAny = "train --no-vgg --patches 1 --patch-size 16 --max-steps 1 --out {d}/run ";
const std::string kTrain = kTrainAny + "--config " + GDSR_SOURCE_DIR + "/configs/tiny.json ";
const std::string kImport =
    "data import-md --lr-dir {d}/badexp/lr --hr-dir {d}/badexp/hr --lr-uv {d}/badexp/lr_flat.obj "
    "--hr-uv {d}/badexp/hr_flat.obj --out {d}/out_ds";
const std::string kImportOk =
    "data import-md --lr-dir {d}/exp_md/lr --hr-dir {d}/exp_md/hr "
    "--lr-uv {d}/exp_md/lr_flat.obj --hr-uv {d}/exp_md/hr_flat.obj ";
const std::string kMake = "data make --garment skirt_short --seconds 0.1 --lr-pd 0.08 --hr-pd 0.06 --out {d}/out_ds ";
const std::string kOwn =
    "infer --model {d}/run/model.ckpt --out {d}/pred --subdivide 1 --lr-dir {d}/badexp/lr "
    "--lr-uv {d}/badexp/lr_flat.obj";

// A dataset array's first payload byte: after magic, type, rank and `rank` dimensions.
long payload(int rank) { return 16 + 8L * rank; }

std::vector<Case> corpus() {
  using S = const std::string&;
  std::vector<Case> c = {
      // ---- data make: flags (refused before simulating)
      {kMake + "--raster 0", "--raster"},
      {kMake + "--raster 100000", "--raster"},
      {kMake + "--seconds -1", "--seconds"},
      {kMake + "--seconds nan", "--seconds"},
      {kMake + "--fps 0", "--fps"},
      {kMake + "--fps 100000", "--fps"},
      {kMake + "--substeps -3", "--substeps"},
      {kMake + "--iterations 0", "--iterations"},
      {kMake + "--friction nan", "--friction"},
      {kMake + "--rest-blend -1", "--rest-blend"},
      {kMake + "--start -1", "--start"},
      {"data make --out {d}/out_ds --lr-pd 0.03 --hr-pd 0.05", "coarser than the LR one"},
      {"data make --out {d}/out_ds --hr-pd 1e-4", "--hr-pd"},
      {kMake + "--garment no_such_garment", "no_such_garment"},
      {kMake + "--motion {d}/none.bvh", "none.bvh"},
      {"data make --garment skirt_short --out {d}/mine", "mine"},
      {"data make --garment skirt_short --out {d}/p.png", "p.png"},
      {"data make --garment skirt_short --out {d}/p.png/ds", "p.png"},
      // ---- data check / preview: flags and folders
      {"data check --data {d}/missing", "missing"},
      {"data check --data {d}/p.png", "p.png"},
      {"data check --data {d}/ds --intersection-stride 0", "--intersection-stride"},
      {"data preview --data {d}/ds --frame 999 --out {d}/p.png", "--frame"},
      {"data preview --data {d}/ds --frame -2 --out {d}/p.png", "--frame"},
      {"data preview --data {d}/ds --size 0 --out {d}/p.png", "--size"},
      {"data preview --data {d}/ds --view side --out {d}/p.png", "--view"},
      {"data preview --data {d}/ds --size 100000 --out {d}/p.png", "--size"},
      {"data preview --data {d}/ds --out {d}/nodir/p.png", "nodir"},
      {"data preview --data {d}/bad --out {d}/p.png", "lr_frames.bin",
       bad_ds([](S b) { cut(b + "/lr_frames.bin", 30); })},
      // ---- dataset files: manifest.json
      {kCheck, "manifest.json", bad_ds([](S b) { put(b + "/manifest.json", "{\"version\": 1,"); })},
      {kCheck, "manifest.json", bad_ds([](S b) { put(b + "/manifest.json", ""); })},
      {kCheck, "manifest.json", bad_ds([](S b) { put(b + "/manifest.json", "[1, 2, 3]"); })},
      {kCheck, "manifest.json", bad_ds([](S b) { fs::remove(b + "/manifest.json"); })},
      {kCheck, "manifest.json", bad_ds([](S b) { json_set(b + "/manifest.json", "/version", 99); })},
      {kCheck, "manifest.json", bad_ds([](S b) { json_set(b + "/manifest.json", "/frames", -1); })},
      {kCheck, "manifest.json", bad_ds([](S b) { json_set(b + "/manifest.json", "/frames", "four"); })},
      {kCheck, "frames", bad_ds([](S b) { json_set(b + "/manifest.json", "/frames", 5); })},
      {kCheck, "manifest.json", bad_ds([](S b) { json_set(b + "/manifest.json", "/lr", nullptr); })},
      {kCheck, "vertices", bad_ds([](S b) { json_set(b + "/manifest.json", "/hr/vertices", 80); })},
      {kCheck, "manifest.json", bad_ds([](S b) { json_set(b + "/manifest.json", "/fps", -30); })},
      {kCheck, "manifest.json", bad_ds([](S b) { json_set(b + "/manifest.json", "/body/vertices", 1e15); })},
      {kCheck, "body_frames.bin", bad_ds([](S b) { json_set(b + "/manifest.json", "/body/vertices", 10); })},
      {kCheck, "uv_raster", bad_ds([](S b) { json_set(b + "/manifest.json", "/uv_raster/width", 95); })},
      // ---- dataset files: arrays
      {kCheck, "lr_frames.bin", bad_ds([](S b) { cut(b + "/lr_frames.bin", -9); })},
      {kCheck, "lr_frames.bin", bad_ds([](S b) { cut(b + "/lr_frames.bin", 5); })},
      {kCheck, "lr_frames.bin", bad_ds([](S b) { flip(b + "/lr_frames.bin", 0); })},
      {kCheck, "hr_frames.bin", bad_ds([](S b) { flip(b + "/hr_frames.bin", payload(3) + 7); })},
      {kCheck, "hr_frames.bin", bad_ds([](S b) { flip(b + "/hr_frames.bin", 8); })},
      {kCheck, "hr_frames.bin", bad_ds([](S b) { flip(b + "/hr_frames.bin", 12); })},
      {kCheck, "hr_frames.bin", bad_ds([](S b) { put(b + "/hr_frames.bin", ""); })},
      {kCheck, "hr_frames.bin", bad_ds([](S b) { fs::remove(b + "/hr_frames.bin"); })},
      {kCheck, "lr_frames.bin", bad_ds([](S b) {
         set_shape(b + "/lr_frames.bin", gdsr::DType::f32, {4, 25, 2});
       })},
      {kCheck, "lr_frames.bin", bad_ds([](S b) {
         set_shape(b + "/lr_frames.bin", gdsr::DType::i32, {4, 25, 3});
       })},
      {kCheck, "lr_frames.bin", bad_ds([](S b) {
         set_shape(b + "/lr_frames.bin", gdsr::DType::f32, {1, 1, 1, 1, 1, 1, 1, 1, 1});
       })},
      {kCheck, "lr_frames.bin", bad_ds([](S b) {
         set_shape(b + "/lr_frames.bin", gdsr::DType::f32, {uint64_t(1) << 62, 4, 3});
       })},
      {kCheck, "lr_frames.bin", bad_ds([](S b) { set_element(b + "/lr_frames.bin", 7, NAN); })},
      {kCheck, "hr_frames.bin", bad_ds([](S b) { set_element(b + "/hr_frames.bin", 4, INFINITY); })},
      {kCheck, "hr_frames.bin", bad_ds([](S b) { set_element(b + "/hr_frames.bin", 4, 1e30); })},
      {kCheck, "hr_layer.bin", bad_ds([](S b) { set_element(b + "/hr_layer.bin", 3, -1); })},
      {kCheck, "lr_layer.bin", bad_ds([](S b) { set_element(b + "/lr_layer.bin", 3, 1e6); })},
      {kCheck, "corr_hr_from_lr_tri.bin", bad_ds([](S b) { set_element(b + "/corr_hr_from_lr_tri.bin", 2, 9999); })},
      {kCheck, "corr_hr_from_lr_tri.bin", bad_ds([](S b) { set_element(b + "/corr_hr_from_lr_tri.bin", 2, -5); })},
      {kCheck, "corr_hr_from_lr_bary.bin", bad_ds([](S b) { set_element(b + "/corr_hr_from_lr_bary.bin", 1, NAN); })},
      {kCheck, "corr_hr_from_lr_bary.bin", bad_ds([](S b) { set_element(b + "/corr_hr_from_lr_bary.bin", 1, 1e6); })},
      {kCheck, "corr_lr_from_hr_tri.bin", bad_ds([](S b) { set_element(b + "/corr_lr_from_hr_tri.bin", 0, 1e8); })},
      {kCheck, "corr_hr_nearest_lr.bin", bad_ds([](S b) { set_element(b + "/corr_hr_nearest_lr.bin", 0, 25); })},
      {kCheck, "uv_raster_tri.bin", bad_ds([](S b) { set_element(b + "/uv_raster_tri.bin", 500, 1e7); })},
      {kCheck, "uv_raster_bary.bin", bad_ds([](S b) { set_element(b + "/uv_raster_bary.bin", 3000, NAN); })},
      {kCheck, "uv_raster_bary.bin", bad_ds([](S b) { set_element(b + "/uv_raster_bary.bin", 3000, 1e6); })},
      {kCheck, "uv_raster_tri.bin", bad_ds([](S b) {
         set_shape(b + "/uv_raster_tri.bin", gdsr::DType::i32, {96, 95});
       })},
      {kCheck, "hr_frames.bin", bad_ds([](S b) {
         fs::remove(b + "/hr_frames.bin");
         fs::create_directories(b + "/hr_frames.bin");
       })},
      // ---- dataset files: the canonical OBJs
      {kCheck, "lr.obj", bad_ds([](S b) { fs::remove(b + "/lr.obj"); })},
      {kCheck, "lr.obj", bad_ds([](S b) { put(b + "/lr.obj", ""); })},
      {kCheck, "hr.obj", bad_ds([](S b) { replace(b + "/hr.obj", "f ", "f x"); })},
      {kCheck, "hr.obj", bad_ds([](S b) { replace(b + "/hr.obj", "v ", "v nan "); })},
      {kCheck, "lr.obj", bad_ds([](S b) { replace(b + "/lr.obj", "f 1/", "f 999/"); })},
      {kCheck, "hr.obj", bad_ds([](S b) { replace(b + "/hr.obj", "vt ", "vt 1e400 "); })},
      {kCheck, "lr.obj", bad_ds([](S b) { put(b + "/lr.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"); })},
      // ---- a bad dataset reaches train, infer and eval the same way
      {kTrain + "--data {d}/bad", "hr_frames.bin", bad_ds([](S b) { set_element(b + "/hr_frames.bin", 4, NAN); })},
      {kTrain + "--data {d}/ds --val-data {d}/bad", "manifest.json",
       bad_ds([](S b) { put(b + "/manifest.json", "{"); })},
      {kInfer + "{d}/bad", "lr_frames.bin", bad_ds([](S b) { cut(b + "/lr_frames.bin", -1); })},
      {"eval --no-export --model {d}/run/model.ckpt --data {d}/bad", "hr.obj",
       bad_ds([](S b) { put(b + "/hr.obj", "v 0 0 0\n"); })},
      // ---- train: flags, configs, resume checkpoints
      {kTrain + "--data {d}/ds --epochs 0", "--epochs"},
      {kTrain + "--data {d}/ds --epochs -1", "--epochs"},
      {kTrain + "--data {d}/ds --max-steps 0", "--max-steps"},
      {kTrain + "--data {d}/ds --lr nan", "--lr"},
      {kTrain + "--data {d}/ds --lr -1", "--lr"},
      {kTrain + "--data {d}/ds --patches 0", "--patches"},
      {kTrain + "--data {d}/ds --patch-size 100000", "--patch-size"},
      {kTrain + "--data {d}/ds --frames-per-step 0", "--frames-per-step"},
      {kTrain + "--data {d}/ds --checkpoint-every -1", "--checkpoint-every"},
      {kTrain + "--data {d}/missing", "missing"},
      {kTrainAny + "--data {d}/ds --config {d}/none.json", "none.json"},
      {kTrainAny + "--data {d}/ds --config {d}/bad.json", "bad.json", text_json("{\"mp_steps\": ")},
      {kTrainAny + "--data {d}/ds --config {d}/bad.json", "bad.json",
       bad_json([](S j) { json_set(j, "/mp_stepz", 2); })},
      {kTrainAny + "--data {d}/ds --config {d}/bad.json", "mp_steps",
       bad_json([](S j) { json_set(j, "/mp_steps", -2); })},
      {kTrainAny + "--data {d}/ds --config {d}/bad.json", "decoder",
       bad_json([](S j) { json_set(j, "/decoder", "wide"); })},
      {kTrainAny + "--data {d}/ds --config {d}/bad.json", "e_widths", bad_json([](S j) {
         json_set(j, "/e_widths", nlohmann::json::array({0, 8}));
       })},
      {kTrainAny + "--data {d}/ds --config {d}/bad.json", "sigma_b",
       bad_json([](S j) { json_set(j, "/sigma_b", -1); })},
      {kTrainAny + "--data {d}/ds --config {d}/bad.json", "bad.json", text_json("[]")},
      {kTrain + "--data {d}/ds --loss-config {d}/bad.json", "bad.json", text_json("{\"coarse\": {")},
      {kTrain + "--data {d}/ds --loss-config {d}/bad.json", "bad.json", text_json("{\"coarze\": {}}")},
      {kTrain + "--data {d}/ds --loss-config {d}/bad.json", "bad.json",
       text_json("{\"schedule\": {\"every_epochs\": 0}}")},
      {kTrain + "--data {d}/ds --loss-config {d}/none.json", "none.json"},
      {kTrain + "--data {d}/ds --resume {d}/none.ckpt", "none.ckpt"},
      {kTrain + "--data {d}/ds --resume {d}/bad.ckpt", "bad.ckpt", bad_ckpt([](S k) { cut(k, -3); })},
      {kTrain + "--data {d}/ds --resume {d}/bad.ckpt", "bad.ckpt", bad_ckpt([](S k) { flip(k, 40); })},
      // ---- checkpoints read by infer
      {kInferBad, "bad.ckpt", bad_ckpt([](S k) { put(k, ""); })},
      {kInferBad, "bad.ckpt", bad_ckpt([](S k) { cut(k, 20); })},
      {kInferBad, "bad.ckpt", bad_ckpt([](S k) { cut(k, -100); })},
      {kInferBad, "bad.ckpt", bad_ckpt([](S k) { flip(k, 0); })},
      {kInferBad, "bad.ckpt", bad_ckpt([](S k) { flip(k, 8); })},
      {kInferBad, "bad.ckpt", bad_ckpt([](S k) { flip(k, 17); })},
      {kInferBad, "bad.ckpt", bad_ckpt([](S k) { flip(k, 100); })},
      {kInferBad, "bad.ckpt", bad_ckpt([](S k) { flip(k, -1); })},
      {kInferBad, "bad.ckpt", bad_ckpt([](S k) { put(k, "GDSRCKPT this is text\n"); })},
      {"infer --data {d}/ds --out {d}/pred --model {d}/none.ckpt", "none.ckpt"},
      {"weights --out {d}/w.ckpt --model {d}/none.ckpt", "none.ckpt"},
      {"weights --out {d}/w.ckpt --model {d}/bad.ckpt", "bad.ckpt", bad_ckpt([](S k) { flip(k, 100); })},
      {"infer --data {d}/ds --out {d}/pred --model {d}/ds", "ds"},
      // ---- infer: flags
      {kInfer + "{d}/ds --frames 0", "--frames"},
      {kInfer + "{d}/ds --frames -5", "--frames"},
      {kInfer + "{d}/ds --first -1", "--first"},
      {kInfer + "{d}/ds --first 99", "--first"},
      {kInfer + "{d}/ds --first 2 --frames 9", "--frames"},
      {kInfer + "{d}/ds --obj-every -1", "--obj-every"},
      {kInfer + "{d}/ds --ablate everything", "--ablate"},
      {kInfer + "{d}/ds --layer-offset -0.01", "--layer-offset"},
      {kInfer + "{d}/ds --layer-offset 0.5", "--layer-offset"},
      {kInfer + "{d}/missing", "missing"},
      {kInfer + "{d}/ds --lr-dir {d}/exp_md/lr", "--lr-dir"},
      {"infer --model {d}/run/model.ckpt --out {d}/pred --subdivide 1 --lr-dir {d}/exp_md/lr "
       "--lr-uv {d}/exp_md/lr_flat.obj --true-history",
       "--true-history"},  // an own sequence has no HR simulation
      {"infer --model {d}/run/model.ckpt --out {d}/pred", "--data"},
      {"infer --model {d}/run/model.ckpt --data {d}/ds --out {d}/p.png", "p.png"},
      // ---- infer on an own OBJ sequence
      {kOwn, "f1.obj", bad_exports([](S e) { replace(e + "/lr/f1.obj", "f ", "f 0 "); })},
      {kOwn, "lr_flat.obj", bad_exports([](S e) { put(e + "/lr_flat.obj", "v 0 0 0\n"); })},
      {kOwn + " --subdivide 3", "--subdivide", bad_exports([](S) {})},
      {kOwn + " --scale 0", "--scale", bad_exports([](S) {})},
      // ---- predictions read by eval and export
      {kEvalBad, "prediction.json", bad_pred([](S p) { put(p + "/prediction.json", "{\"first_frame\": 0,"); })},
      {kEvalBad, "prediction.json", bad_pred([](S p) { fs::remove(p + "/prediction.json"); })},
      {kEvalBad, "prediction.json", bad_pred([](S p) { json_set(p + "/prediction.json", "/frames", nullptr); })},
      {kEvalBad, "prediction.json", bad_pred([](S p) { json_set(p + "/prediction.json", "/first_frame", "zero"); })},
      {kEvalBad, "records 5", bad_pred([](S p) { json_set(p + "/prediction.json", "/frames", 5); })},
      {kEvalBad, "covers frames", bad_pred([](S p) { json_set(p + "/prediction.json", "/first_frame", 2); })},
      {kEvalBad, "covers frames", bad_pred([](S p) { json_set(p + "/prediction.json", "/first_frame", -3); })},
      {kEvalBad, "was made on", bad_pred([](S p) { json_set(p + "/prediction.json", "/dataset", "/elsewhere"); })},
      {kEvalBad, "pred_hr.bin", bad_pred([](S p) { cut(p + "/pred_hr.bin", -5); })},
      {kEvalBad, "pred_hr.bin", bad_pred([](S p) { flip(p + "/pred_hr.bin", payload(3) + 2); })},
      {kEvalBad, "pred_hr.bin", bad_pred([](S p) { fs::remove(p + "/pred_hr.bin"); })},
      {kEvalBad, "pred_hr.bin", bad_pred([](S p) { set_element(p + "/pred_hr.bin", 5, NAN); })},
      {kEvalBad, "HR vertices", bad_pred([](S p) {
         set_shape(p + "/pred_hr.bin", gdsr::DType::f32, {4, 80, 3});
       })},
      {kEvalBad, "pred_hr.bin", bad_pred([](S p) {
         set_shape(p + "/pred_hr.bin", gdsr::DType::f32, {4, 81});
       })},
      {kEvalBad + " --first 1", "--first"},
      {"eval --no-export --data {d}/ds --pred {d}/missing", "missing"},
      {"eval --no-export --data {d}/ds --pred {d}/pred --ssim-every 0", "--ssim-every"},
      {"eval --data {d}/ds --pred {d}/pred --report {d}/rep --video-every 0", "--video-every"},
      {"eval --data {d}/ds --pred {d}/pred --report {d}/p.png", "p.png"},
      {"export --data {d}/ds --pred {d}/badpred --out {d}/exp", "pred_hr.bin",
       bad_pred([](S p) { set_element(p + "/pred_hr.bin", 0, INFINITY); })},
      {"export --data {d}/ds --pred {d}/badpred --out {d}/exp", "prediction.json",
       bad_pred([](S p) { put(p + "/prediction.json", "null"); })},
      {"export --data {d}/ds --pred {d}/pred --out {d}/exp --formats gltf,fbx", "--formats"},
      {"export --data {d}/ds --pred {d}/pred --out {d}/exp --sequences gdsr,xx", "--sequences"},
      {"export --data {d}/ds --pred {d}/pred --out {d}/exp --obj-every 0", "--obj-every"},
      {"export --data {d}/ds --pred {d}/pred --out {d}/p.png", "p.png"},
      // ---- data import-md: flags and OBJ exports
      {kImportOk + "--out {d}/out_ds --fps 0", "--fps"},
      {kImportOk + "--out {d}/out_ds --scale 0", "--scale"},
      {kImportOk + "--out {d}/out_ds --scale nan", "--scale"},
      {kImportOk + "--out {d}/out_ds --weld -1", "--weld"},
      {kImportOk + "--out {d}/exp_md", "exp_md"},
      {kImportOk + "--out {d}/exp_md/lr/ds", "overlaps the input"},
      {kImportOk + "--out {d}/p.png", "p.png"},
      {"data import-md --lr-dir {d}/none --hr-dir {d}/exp_md/hr --lr-uv {d}/exp_md/lr_flat.obj "
       "--hr-uv {d}/exp_md/hr_flat.obj --out {d}/out_ds",
       "none"},
      {kImport, "f1.obj", bad_exports([](S e) { replace(e + "/hr/f1.obj", "f ", "f x"); })},
      {kImport, "f1.obj", bad_exports([](S e) { replace(e + "/hr/f1.obj", "v ", "v NaN "); })},
      {kImport, "f1.obj", bad_exports([](S e) { replace(e + "/hr/f1.obj", "v ", "v 1e39 "); })},
      {kImport, "f2.obj", bad_exports([](S e) { replace(e + "/lr/f2.obj", "f 1 ", "f 99 "); })},
      {kImport, "f2.obj", bad_exports([](S e) { replace(e + "/lr/f2.obj", "v ", "v 1 2 3\nv "); })},
      {kImport, "f2.obj", bad_exports([](S e) { replace(e + "/lr/f2.obj", "f 1 ", "f 2 "); })},
      {kImport, "f2.obj", bad_exports([](S e) { put(e + "/hr/f2.obj", ""); })},
      {kImport, "lr_flat.obj", bad_exports([](S e) { replace(e + "/lr_flat.obj", " 0\n", " 0.5\n"); })},
      {kImport, "hr_flat.obj",
       bad_exports([](S e) { put(e + "/hr_flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"); })},
      {kImport, "lr_flat.obj", bad_exports([](S e) { fs::remove(e + "/lr_flat.obj"); })},
      {kImport, "f5.obj", bad_exports([](S e) { fs::rename(e + "/lr/f2.obj", e + "/lr/f5.obj"); })},
      {kImport, "appears twice", bad_exports([](S e) { fs::copy_file(e + "/lr/f1.obj", e + "/lr/f01.obj"); })},
      {kImport, "notes.obj", bad_exports([](S e) { fs::copy_file(e + "/lr/f1.obj", e + "/lr/notes.obj"); })},
      {kImport, "frame counts", bad_exports([](S e) { fs::remove(e + "/hr/f2.obj"); })},
      {kImport, "hr", bad_exports([](S e) {
         for (const auto& f : fs::directory_iterator(e + "/hr")) fs::remove(f.path());
       })},
      {kImport + " --body-dir {d}/badexp/body", "body", bad_exports([](S e) { fs::create_directories(e + "/body"); })},
      // ---- a full disk: every writer fails cleanly and keeps what was there
      {kImportOk + "--out {d}/out_ds", "out_ds.tmp.", {}, full_disk(16)},
      {kInfer + "{d}/ds", "pred", {}, full_disk(2)},
      {"export --data {d}/ds --pred {d}/pred --out {d}/exp", "exp", {}, full_disk(2)},
      {"eval --data {d}/ds --pred {d}/pred --report {d}/rep", "rep", {}, full_disk(2)},
      {"data preview --data {d}/ds --size 512 --out {d}/p.png", "p.png", {}, full_disk(8)},
      {kTrain + "--data {d}/ds --seed 7", "run", {}, full_disk(1)},
  };
  return c;
}

// Every file under `dir` (but the runner's stdout / stderr) with its size and bytes.
std::string tree(const TempDir& d) {
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(d.path)) {
    const std::string n = e.path().filename().string();
    if (n != "stdout.txt" && n != "stderr.txt") files.push_back(e.path().string() + (e.is_directory() ? "/" : ""));
  }
  std::sort(files.begin(), files.end());
  std::string all;
  for (const auto& f : files) all += f + "\n" + (f.back() == '/' ? std::string() : slurp(f));
  return all;
}

std::string expand(std::string s, const std::string& dir) {
  for (size_t p; (p = s.find("{d}")) != std::string::npos;) s.replace(p, 3, dir);
  return s;
}

}  // namespace

TEST_CASE("cli corpus: every bad input gets one line naming it and changes nothing") {
  TempDir d("corpus");
  // Fixtures, each made once: a 4-frame dataset, a one-step run, its prediction and export,
  // MD-style exports, a preview PNG, a dataset at out_ds and a user's folder.
  gdsr::write_dataset(d / "ds", gdsr_test::wave_dataset(4));
  gdsr::write_dataset(d / "out_ds", gdsr_test::wave_dataset(3));
  {
    TempDir e("corpus_md");
    gdsr_test::write_exports(e, 3);
    fs::create_directories(d / "exp_md");
    for (const char* n : {"lr", "hr", "lr_flat.obj", "hr_flat.obj"})
      fs::copy(e / n, d / ("exp_md/" + std::string(n)), fs::copy_options::recursive);
  }
  fs::create_directories(d / "mine");
  put(d / "mine/notes.txt", "my notes\n");
  REQUIRE(gdsr_run(d, expand(kTrain + "--data {d}/ds", d.path.string())).status == 0);
  REQUIRE(gdsr_run(d, expand(kInfer + "{d}/ds", d.path.string())).status == 0);
  REQUIRE(gdsr_run(d, expand("export --data {d}/ds --pred {d}/pred --out {d}/exp", d.path.string())).status == 0);
  REQUIRE(gdsr_run(d, expand("data preview --data {d}/ds --size 64 --out {d}/p.png", d.path.string())).status == 0);

  const std::vector<Case> cases = corpus();
  CHECK(cases.size() >= 80);
  MESSAGE(cases.size() << " bad inputs");
  for (const Case& c : cases) {
    for (const char* s : kScratch) fs::remove_all(d / s);
    if (c.setup) c.setup(d);
    const std::string args = expand(c.args, d.path.string());
    INFO("gdsr " << args);
    const std::string before = tree(d);
    // The passive OpenMP wait policy set here spares gdsr its re-exec (autograd/runtime.hpp).
    const Run r = gdsr_run(d, args, c.prefix + "OMP_WAIT_POLICY=passive ");
    // As check_one_line_error, but never fatal: every case runs and reports.
    const size_t at = r.err.find("gdsr: error: ");
    const std::string line = at == std::string::npos ? "" : r.err.substr(at);
    const bool changed = tree(d) != before;
    bool leaked = false;
    for (const char* leak : {"std::", "json.exception", "max_size", "bad_alloc", "basic_string", "stoi", "stod"})
      leaked = leaked || r.err.find(leak) != std::string::npos;
    CHECK(r.status == 1);
    CHECK(line.find('\n') == line.size() - 1);  // one line, the last one
    CHECK(line.find(c.needle) != std::string::npos);
    CHECK_FALSE(leaked);
    CHECK_FALSE(changed);
    if (r.status != 1 || line.find(c.needle) == std::string::npos || leaked || changed)
      MESSAGE("exit " << r.status << std::string(changed ? ", folder changed" : "") << ", expected '" << c.needle
                      << "' in: " << (line.empty() ? r.err : line));
  }
  for (const char* s : kScratch) fs::remove_all(d / s);
}

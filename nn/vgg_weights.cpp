#include "nn/vgg_weights.hpp"

#include "autograd/tensor.hpp"

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace nn {

const std::vector<std::string>& vgg19_conv_names() {
  static const std::vector<std::string> names = {"conv1_1", "conv1_2", "conv2_1", "conv2_2", "conv3_1", "conv3_2",
                                                 "conv3_3", "conv3_4", "conv4_1", "conv4_2", "conv4_3", "conv4_4",
                                                 "conv5_1", "conv5_2", "conv5_3", "conv5_4"};
  return names;
}

std::string vgg19_default_dir() {
  if (const char* env = std::getenv("GDSR_VGG19_WEIGHTS"); env && *env) return env;
  namespace fs = std::filesystem;
  const fs::path rel = fs::path("shared") / "weights" / "vgg19-imagenet-conv1-conv3";
  // The repository sits beside shared/ and the executable is built inside it (build/gdsr),
  // so shared/ is a child of one of the executable's ancestors, whatever the working folder.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec)
    for (fs::path p = exe.parent_path(); !p.empty(); p = p.parent_path()) {
      if (fs::exists(p / rel / "model.json", ec)) return (p / rel).string();
      if (p == p.parent_path()) break;
    }
  return (fs::path("..") / rel).string();  // relative to the working folder (the old default)
}

VggWeights load_vgg19_keras(const std::string& dir) {
  const std::string json_path = dir + "/model.json";
  std::ifstream jf(json_path);
  if (!jf)
    throw ag::Error("VGG19 weights not found: cannot open '" + json_path +
                    "' (expected the Keras/TF.js VGG19 files there)");
  nlohmann::json model;
  try {
    jf >> model;
  } catch (const std::exception& e) {
    throw ag::Error("VGG19 weights: '" + json_path + "' is not valid JSON: " + e.what());
  }
  if (!model.contains("weightsManifest") || !model["weightsManifest"].is_array())
    throw ag::Error("VGG19 weights: '" + json_path + "' has no weightsManifest");

  VggWeights out;
  out.preprocess = VggPreprocess::CaffeBGR;
  out.source = dir;
  const auto& names = vgg19_conv_names();
  for (const auto& group : model["weightsManifest"]) {
    if (out.convs.size() == names.size()) break;
    const auto& ws = group.at("weights");
    if (ws.size() != 2) break;
    const std::string kname = ws[0].at("name"), bname = ws[1].at("name");
    if (kname.find("conv") == std::string::npos || kname.find("/kernel") == std::string::npos) break;
    const auto kshape = ws[0].at("shape").get<std::vector<int64_t>>();
    const auto bshape = ws[1].at("shape").get<std::vector<int64_t>>();
    if (kshape.size() != 4 || kshape[0] != 3 || kshape[1] != 3 || bshape.size() != 1 || bshape[0] != kshape[3])
      throw ag::Error("VGG19 weights: '" + json_path + "': layer " + kname + " is not a 3x3 convolution");
    const std::string file = dir + "/" + group.at("paths").at(0).get<std::string>();
    std::ifstream bf(file, std::ios::binary | std::ios::ate);
    if (!bf) {
      // Manifest entries beyond the shipped files (blocks 4, 5) simply end the list.
      if (out.convs.size() >= 1) break;
      throw ag::Error("VGG19 weights not found: cannot open '" + file + "'");
    }
    const int64_t I = kshape[2], O = kshape[3];
    const int64_t nk = 9 * I * O, nb = O;
    const std::streamoff size = bf.tellg();
    if (size != static_cast<std::streamoff>((nk + nb) * 4))
      throw ag::Error("VGG19 weights: '" + file + "' has " + std::to_string(size) + " bytes, expected " +
                      std::to_string((nk + nb) * 4) + " for " + kname);
    std::vector<float> raw(static_cast<size_t>(nk + nb));
    bf.seekg(0);
    bf.read(reinterpret_cast<char*>(raw.data()), size);
    if (!bf) throw ag::Error("VGG19 weights: read failed on '" + file + "'");
    VggConv c;
    c.name = names[out.convs.size()];
    c.in = I;
    c.out = O;
    if (!out.convs.empty() && out.convs.back().out != I)
      throw ag::Error("VGG19 weights: '" + json_path + "': " + kname + " takes " + std::to_string(I) +
                      " channels, the previous layer gives " + std::to_string(out.convs.back().out));
    c.weight.resize(static_cast<size_t>(nk));
    // HWIO [ky][kx][i][o] -> OIHW [o][i][ky][kx]
    for (int64_t ky = 0; ky < 3; ++ky)
      for (int64_t kx = 0; kx < 3; ++kx)
        for (int64_t i = 0; i < I; ++i)
          for (int64_t o = 0; o < O; ++o)
            c.weight[((o * I + i) * 3 + ky) * 3 + kx] = raw[((ky * 3 + kx) * I + i) * O + o];
    c.bias.assign(raw.begin() + nk, raw.end());
    out.convs.push_back(std::move(c));
  }
  if (out.convs.empty()) throw ag::Error("VGG19 weights: '" + json_path + "' lists no convolution layers");
  if (out.convs.front().in != 3)
    throw ag::Error("VGG19 weights: '" + json_path + "': the first layer takes " +
                    std::to_string(out.convs.front().in) + " channels, expected 3");
  return out;
}

}  // namespace nn

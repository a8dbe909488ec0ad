// VGG19 convolution weights in memory, independent of where they came from, and the
// loader for the shared Keras/TensorFlow.js files.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace nn {

// What the first convolution expects as input.
//  CaffeBGR: pixels 0..255, channel order B, G, R, minus the mean pixel (103.939, 116.779,
//            123.68); Keras "caffe" mode and the original Oxford Caffe model.
//  TorchRGB: RGB in 0..1, minus mean (0.485, 0.456, 0.406), divided by std (0.229, 0.224,
//            0.225); torchvision's VGG19 (e.g. exported to ONNX).
enum class VggPreprocess { CaffeBGR, TorchRGB };

struct VggConv {
  std::string name;           // e.g. "conv1_1"
  int64_t in = 0, out = 0;    // channels
  std::vector<float> weight;  // [out x in x 3 x 3] (cross-correlation, PyTorch/Caffe layout)
  std::vector<float> bias;    // [out]
};

struct VggWeights {
  std::vector<VggConv> convs;  // the first convs.size() convolutions of VGG19, in order
  VggPreprocess preprocess = VggPreprocess::CaffeBGR;
  std::string source;  // path(s) the weights came from (for messages)
};

// VGG19's 16 convolution names in order: conv1_1, conv1_2, conv2_1, ..., conv5_4.
const std::vector<std::string>& vgg19_conv_names();

// The shared weights directory: $GDSR_VGG19_WEIGHTS if set, else
// "<A>/shared/weights/vgg19-imagenet-conv1-conv3" for the nearest ancestor A of the running
// executable's folder that holds it (any working folder), else that path under "..".
std::string vgg19_default_dir();

// Reads <dir>/model.json (weightsManifest) and its group files (float32 little-endian,
// Keras HWIO kernel then bias), converting kernels to [out x in x 3 x 3]. Preprocess:
// CaffeBGR. Throws ag::Error naming the missing or malformed file; never substitutes.
VggWeights load_vgg19_keras(const std::string& dir);

}  // namespace nn

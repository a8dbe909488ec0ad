// Loading VGG19 convolution weights from any file OpenCV's dnn module reads (Caffe
// prototxt + caffemodel, ONNX, ...): the Convolution layers' blobs are taken in network
// order as conv1_1, conv1_2, ... Header-only so that gdsr_nn itself does not depend on
// OpenCV; include it from code that links OpenCV (gdsr_core and above).
#pragma once

#include "autograd/tensor.hpp"
#include "nn/vgg_weights.hpp"

#include <opencv2/dnn.hpp>

#include <string>

namespace nn {

// model: weights file (.caffemodel, .onnx, ...); config: .prototxt for Caffe ("" for ONNX).
// preprocess: what the file's first layer expects (CaffeBGR for the Oxford Caffe model,
// TorchRGB for torchvision exports). At most 16 convolutions are taken (VGG19's).
inline VggWeights load_vgg19_opencv(const std::string& model, const std::string& config, VggPreprocess preprocess) {
  cv::dnn::Net net;
  try {
    net = cv::dnn::readNet(model, config);
  } catch (const cv::Exception& e) {
    throw ag::Error("VGG19 weights: OpenCV cannot read '" + model + "'" +
                    (config.empty() ? "" : " / '" + config + "'") + ": " + e.what());
  }
  if (net.empty()) throw ag::Error("VGG19 weights: OpenCV read an empty network from '" + model + "'");
  VggWeights out;
  out.preprocess = preprocess;
  out.source = model;
  const auto& names = vgg19_conv_names();
  for (const std::string& lname : net.getLayerNames()) {
    if (out.convs.size() == names.size()) break;
    cv::Ptr<cv::dnn::Layer> layer = net.getLayer(lname);
    if (layer->type != "Convolution") continue;
    if (layer->blobs.empty())
      throw ag::Error("VGG19 weights: convolution '" + lname + "' in '" + model + "' has no weights");
    const cv::Mat& wb = layer->blobs[0];
    if (wb.dims != 4 || wb.size[2] != 3 || wb.size[3] != 3 || wb.type() != CV_32F)
      throw ag::Error("VGG19 weights: convolution '" + lname + "' in '" + model + "' is not a float 3x3 kernel");
    VggConv c;
    c.name = names[out.convs.size()];
    c.out = wb.size[0];
    c.in = wb.size[1];
    const cv::Mat wc = wb.isContinuous() ? wb : wb.clone();
    c.weight.assign(wc.ptr<float>(), wc.ptr<float>() + c.out * c.in * 9);
    if (layer->blobs.size() > 1) {
      const cv::Mat bb = layer->blobs[1].isContinuous() ? layer->blobs[1] : layer->blobs[1].clone();
      if (static_cast<int64_t>(bb.total()) != c.out || bb.type() != CV_32F)
        throw ag::Error("VGG19 weights: convolution '" + lname + "' in '" + model + "' has a bias of the wrong size");
      c.bias.assign(bb.ptr<float>(), bb.ptr<float>() + c.out);
    } else {
      c.bias.assign(static_cast<size_t>(c.out), 0.0f);
    }
    out.convs.push_back(std::move(c));
  }
  if (out.convs.empty()) throw ag::Error("VGG19 weights: no convolution layers in '" + model + "'");
  return out;
}

}  // namespace nn

// Writes VGG weights as a Caffe model (text prototxt + binary caffemodel), the format
// OpenCV's dnn module (cv::dnn::readNet) and Caffe read. Used to hand our weights to an
// independent implementation in tests, and to test the "user supplies a full VGG19" path.
#pragma once

#include "nn/vgg_weights.hpp"

#include <string>

namespace nn {

// The network: input "data" [1 x 3 x height x width] (preprocessed as the weights expect),
// then for each conv: Convolution (3x3, pad 1) + in-place ReLU named "reluB_K", and after
// conv1_2, conv2_2, conv3_4, conv4_4 (when followed by another conv) a 2x2 stride-2
// Pooling, average (avg_pool = true, as our extractor) or max. Blobs: weight
// [out x in x 3 x 3], bias [out]. Both files are written via temp file + rename.
void write_vgg_caffe(const VggWeights& w, const std::string& prototxt_path, const std::string& caffemodel_path,
                     int64_t height, int64_t width, bool avg_pool = true);

}  // namespace nn

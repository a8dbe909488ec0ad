#include "nn/vgg.hpp"

#include "autograd/ops_conv.hpp"
#include "autograd/ops_elementwise.hpp"

#include <algorithm>

namespace nn {

namespace {
// Convolutions after which VGG19 pools (0-based): conv1_2, conv2_2, conv3_4, conv4_4.
bool pool_after(int conv) { return conv == 1 || conv == 3 || conv == 7 || conv == 11; }

int conv_index_of(const std::string& relu) {
  const auto& names = vgg19_conv_names();
  for (size_t i = 0; i < names.size(); ++i)
    if ("relu" + names[i].substr(4) == relu) return static_cast<int>(i);
  return -1;
}
}  // namespace

template <class T> std::vector<std::string> VGG19Features<T>::default_layers(int64_t num_convs) {
  std::vector<std::string> out;
  for (const char* l : {"relu1_2", "relu2_1", "relu3_1", "relu4_1", "relu5_1"})
    if (conv_index_of(l) < num_convs) out.push_back(l);
  return out;
}

template <class T> VGG19Features<T>::VGG19Features(const VggWeights& weights, std::vector<std::string> layers)
    : src_(weights) {
  build(std::move(layers));
}

template <class T> VGG19Features<T>::VGG19Features(const std::string& keras_dir, std::vector<std::string> layers)
    : src_(load_vgg19_keras(keras_dir)) {
  build(std::move(layers));
}

template <class T> void VGG19Features<T>::build(std::vector<std::string> layers) {
  const auto& convs = src_.convs;
  if (convs.empty()) throw ag::Error("VGG19Features: no convolution weights (" + src_.source + ")");
  if (convs.size() > 16) throw ag::Error("VGG19Features: more than 16 convolutions in " + src_.source);
  if (convs[0].in != 3)
    throw ag::Error("VGG19Features: the first convolution must take 3 channels (" + src_.source + ")");
  for (size_t i = 0; i < convs.size(); ++i) {
    const VggConv& c = convs[i];
    if (i > 0 && c.in != convs[i - 1].out)
      throw ag::Error("VGG19Features: " + c.name + " takes " + std::to_string(c.in) +
                      " channels, the previous layer gives " + std::to_string(convs[i - 1].out) + " (" + src_.source +
                      ")");
    if (static_cast<int64_t>(c.weight.size()) != c.out * c.in * 9 || static_cast<int64_t>(c.bias.size()) != c.out)
      throw ag::Error("VGG19Features: " + c.name + " has inconsistent weight sizes (" + src_.source + ")");
  }

  // Preprocessed channel k = s_k * (x_{perm_k} - mu_k), x = RGB in 0..1.
  int perm[3];
  double s[3], mu[3];
  if (src_.preprocess == VggPreprocess::CaffeBGR) {
    const double mean_bgr[3] = {103.939, 116.779, 123.68};
    for (int k = 0; k < 3; ++k) {
      perm[k] = 2 - k;
      s[k] = 255.0;
      mu[k] = mean_bgr[k] / 255.0;
    }
  } else {
    const double mean[3] = {0.485, 0.456, 0.406}, stdv[3] = {0.229, 0.224, 0.225};
    for (int k = 0; k < 3; ++k) {
      perm[k] = k;
      s[k] = 1.0 / stdv[k];
      mu[k] = mean[k];
    }
  }
  for (int k = 0; k < 3; ++k) offset_[perm[k]] = static_cast<T>(mu[k]);

  w_.clear();
  b_.clear();
  for (size_t i = 0; i < convs.size(); ++i) {
    const VggConv& c = convs[i];
    std::vector<T> w(c.weight.size());
    if (i == 0) {
      // conv(p)[o] = sum_k W[o,k] s_k (x_{perm_k} - mu_k) => W'[o, perm_k] = s_k W[o, k]
      for (int64_t o = 0; o < c.out; ++o)
        for (int k = 0; k < 3; ++k)
          for (int t = 0; t < 9; ++t)
            w[(o * 3 + perm[k]) * 9 + t] = static_cast<T>(s[k] * static_cast<double>(c.weight[(o * 3 + k) * 9 + t]));
    } else {
      std::transform(c.weight.begin(), c.weight.end(), w.begin(), [](float v) { return static_cast<T>(v); });
    }
    std::vector<T> b(c.bias.begin(), c.bias.end());
    w_.push_back(ag::Tensor<T>::from({c.out, c.in, 3, 3}, std::move(w), false));
    b_.push_back(ag::Tensor<T>::from({c.out}, std::move(b), false));
  }

  if (layers.empty()) layers = default_layers(num_convs());
  layers_.clear();
  layer_conv_.clear();
  for (const auto& l : layers) {
    const int ci = conv_index_of(l);
    if (ci < 0) throw ag::Error("VGG19Features: unknown layer '" + l + "' (use relu1_1 ... relu5_4)");
    if (ci >= num_convs())
      throw ag::Error("VGG19Features: layer '" + l + "' needs " + vgg19_conv_names()[ci] + ", but the weights from " +
                      src_.source + " stop at " + convs.back().name);
    layers_.push_back(l);
    layer_conv_.push_back(ci);
  }
}

template <class T> std::vector<ag::Tensor<T>> VGG19Features<T>::features(const ag::Tensor<T>& image) const {
  if (image.dim() != 4 || image.size(1) != 3)
    throw ag::Error("VGG19Features: image must be [N x 3 x H x W] RGB, got " + ag::shape_str(image.shape()));
  const int64_t N = image.size(0), H = image.size(2), W = image.size(3);
  const int deepest = *std::max_element(layer_conv_.begin(), layer_conv_.end());
  int pools = 0;
  for (int i = 0; i < deepest; ++i) pools += pool_after(i) ? 1 : 0;
  if ((H >> pools) < 1 || (W >> pools) < 1)
    throw ag::Error("VGG19Features: image " + ag::shape_str(image.shape()) + " is too small for " +
                    std::to_string(pools) + " poolings");

  std::vector<T> off(static_cast<size_t>(N * 3 * H * W));
  for (int64_t n = 0; n < N; ++n)
    for (int c = 0; c < 3; ++c) std::fill_n(off.begin() + (n * 3 + c) * H * W, H * W, -offset_[c]);
  ag::Tensor<T> h = ag::add(image, ag::Tensor<T>::from(image.shape(), std::move(off)));

  std::vector<ag::Tensor<T>> out(layers_.size());
  for (int i = 0; i <= deepest; ++i) {
    h = ag::relu(ag::conv2d_3x3(h, w_[i], b_[i]));
    for (size_t l = 0; l < layers_.size(); ++l)
      if (layer_conv_[l] == i) out[l] = h;
    if (i < deepest && pool_after(i)) h = ag::avg_pool2x2(h);
  }
  return out;
}

template class VGG19Features<float>;
template class VGG19Features<double>;

}  // namespace nn

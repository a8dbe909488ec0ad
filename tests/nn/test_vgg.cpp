// VGG19 features: the shared ImageNet weights, agreement with OpenCV's dnn forward (an
// independent conv/pool implementation) on the same weights and input, the OpenCV file
// loader (for a user's full VGG19), gradients to the image, and the feature losses.
#include "autograd/autograd.hpp"
#include "tests/support/caffe_export.hpp"
#include "nn/feature_loss.hpp"
#include "nn/rng.hpp"
#include "nn/vgg.hpp"
#include "tests/support/vgg_opencv.hpp"

#include <doctest/doctest.h>
#include <opencv2/dnn.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>

namespace {
namespace fs = std::filesystem;

const std::string kWeights = std::string(GDSR_SHARED_DIR) + "/weights/vgg19-imagenet-conv1-conv3";

std::string tmp_path(const std::string& name) {
  const fs::path dir = fs::path(GDSR_BINARY_DIR) / "test_tmp";
  fs::create_directories(dir);
  return (dir / name).string();
}

template <class T> ag::Tensor<T> random_image(int64_t n, int64_t h, int64_t w, uint64_t seed) {
  nn::Rng rng(seed);
  ag::Tensor<T> t = ag::Tensor<T>::zeros({n, 3, h, w});
  for (auto& v : t.values()) v = static_cast<T>(rng.uniform(0, 1));
  return t;
}

// The input blob OpenCV's net expects: the preprocessing written out directly.
cv::Mat preprocess_blob(const ag::Tensorf& img, nn::VggPreprocess pre) {
  const int H = static_cast<int>(img.size(2)), W = static_cast<int>(img.size(3));
  const int sz[4] = {1, 3, H, W};
  cv::Mat blob(4, sz, CV_32F);
  float* b = blob.ptr<float>();
  const float* x = img.data();
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < H * W; ++i) {
      if (pre == nn::VggPreprocess::CaffeBGR) {
        const double mean_bgr[3] = {103.939, 116.779, 123.68};
        b[k * H * W + i] = static_cast<float>(255.0 * x[(2 - k) * H * W + i] - mean_bgr[k]);
      } else {
        const double mean[3] = {0.485, 0.456, 0.406}, stdv[3] = {0.229, 0.224, 0.225};
        b[k * H * W + i] = static_cast<float>((x[k * H * W + i] - mean[k]) / stdv[k]);
      }
    }
  return blob;
}

// max |ours - opencv| / max |opencv| for one feature map.
double rel_error(const ag::Tensorf& ours, const cv::Mat& ref) {
  REQUIRE(ref.dims == 4);
  for (int d = 0; d < 4; ++d) REQUIRE(ref.size[d] == ours.size(d));
  const float* r = ref.ptr<float>();
  double diff = 0, scale = 0;
  for (int64_t i = 0; i < ours.numel(); ++i) {
    diff = std::max(diff, std::abs(double(ours.data()[i]) - double(r[i])));
    scale = std::max(scale, std::abs(double(r[i])));
  }
  REQUIRE(scale > 0);
  return diff / scale;
}

double compare_with_opencv(const nn::VggWeights& w, const std::string& tag, int64_t H, int64_t W, uint64_t seed) {
  const std::string proto = tmp_path(tag + ".prototxt"), model = tmp_path(tag + ".caffemodel");
  nn::write_vgg_caffe(w, proto, model, H, W, true);
  cv::dnn::Net net = cv::dnn::readNetFromCaffe(proto, model);
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  nn::VGG19Features<float> vgg(w);
  const ag::Tensorf img = random_image<float>(1, H, W, seed);
  net.setInput(preprocess_blob(img, w.preprocess));
  std::vector<cv::Mat> ref;
  std::vector<cv::String> names(vgg.layer_names().begin(), vgg.layer_names().end());
  net.forward(ref, names);
  const auto ours = vgg.features(img);
  REQUIRE(ours.size() == ref.size());
  double worst = 0;
  for (size_t l = 0; l < ours.size(); ++l) {
    const double e = rel_error(ours[l], ref[l]);
    MESSAGE(tag << " " << names[l] << " " << ag::shape_str(ours[l].shape()) << ": max relative error vs OpenCV " << e);
    worst = std::max(worst, e);
  }
  return worst;
}

// A VGG19-shaped net (16 convs) with few channels and random He-scaled weights.
nn::VggWeights narrow_vgg19(uint64_t seed) {
  nn::Rng rng(seed);
  nn::VggWeights w;
  w.preprocess = nn::VggPreprocess::TorchRGB;
  w.source = "synthetic";
  const int64_t widths[16] = {8, 8, 12, 12, 16, 16, 16, 16, 20, 20, 20, 20, 24, 24, 24, 24};
  int64_t in = 3;
  for (int i = 0; i < 16; ++i) {
    nn::VggConv c;
    c.name = nn::vgg19_conv_names()[i];
    c.in = in;
    c.out = widths[i];
    const double std = std::sqrt(2.0 / (9.0 * double(in)));
    for (int64_t k = 0; k < c.out * c.in * 9; ++k) c.weight.push_back(static_cast<float>(rng.normal(0, std)));
    for (int64_t k = 0; k < c.out; ++k) c.bias.push_back(static_cast<float>(rng.uniform(0.0, 0.1)));
    in = c.out;
    w.convs.push_back(std::move(c));
  }
  return w;
}
}  // namespace

TEST_CASE("VGG19: the shared ImageNet weights load with their documented statistics") {
  const nn::VggWeights w = nn::load_vgg19_keras(kWeights);
  REQUIRE(w.convs.size() == 8);
  const int64_t outs[8] = {64, 64, 128, 128, 256, 256, 256, 256};
  for (int i = 0; i < 8; ++i) CHECK(w.convs[i].out == outs[i]);
  auto stats = [](const std::vector<float>& v) {
    double s = 0, s2 = 0;
    for (float x : v) s += x;
    const double m = s / double(v.size());
    for (float x : v) s2 += (x - m) * (x - m);
    return std::make_pair(m, std::sqrt(s2 / double(v.size())));
  };
  // README: block1_conv1 kernel mean -0.0020 std 0.1914, bias mean 0.4678;
  // block3_conv4 kernel std 0.0103, bias mean 0.0188.
  CHECK(stats(w.convs[0].weight).first == doctest::Approx(-0.0020).epsilon(0.03));
  CHECK(stats(w.convs[0].weight).second == doctest::Approx(0.1914).epsilon(0.001));
  CHECK(stats(w.convs[0].bias).first == doctest::Approx(0.4678).epsilon(0.001));
  CHECK(stats(w.convs[7].weight).second == doctest::Approx(0.0103).epsilon(0.01));
  CHECK(stats(w.convs[7].bias).first == doctest::Approx(0.0188).epsilon(0.01));

  nn::VGG19Features<float> vgg(w);
  CHECK(vgg.layer_names() == std::vector<std::string>{"relu1_2", "relu2_1", "relu3_1"});
  const auto f = vgg.features(random_image<float>(2, 16, 24, 1));
  REQUIRE(f.size() == 3);
  CHECK(f[0].shape() == ag::Shape{2, 64, 16, 24});
  CHECK(f[1].shape() == ag::Shape{2, 128, 8, 12});
  CHECK(f[2].shape() == ag::Shape{2, 256, 4, 6});
  CHECK_THROWS_WITH_AS(nn::VGG19Features<float>(w, {"relu4_1"}), doctest::Contains("conv4_1"), ag::Error);
  CHECK_THROWS_WITH_AS(nn::VGG19Features<float>(w, {"relu9_9"}), doctest::Contains("relu9_9"), ag::Error);
  CHECK_THROWS_AS(vgg.features(ag::Tensorf::zeros({1, 4, 8, 8})), ag::Error);
}

TEST_CASE("VGG19: missing weights give a clear error naming the path") {
  const std::string missing = tmp_path("no_such_vgg_dir");
  CHECK_THROWS_WITH_AS(nn::load_vgg19_keras(missing),
                       doctest::Contains(doctest::String((missing + "/model.json").c_str())), ag::Error);
  CHECK_THROWS_WITH_AS(nn::VGG19Features<float>{missing}, doctest::Contains("not found"), ag::Error);
  CHECK_THROWS_WITH_AS(
      nn::load_vgg19_opencv(missing + "/x.caffemodel", missing + "/x.prototxt", nn::VggPreprocess::CaffeBGR),
      doctest::Contains("x.caffemodel"), ag::Error);
}

TEST_CASE("VGG19: our conv/pool forward matches OpenCV dnn on the shared weights (1e-4 relative)") {
  const nn::VggWeights w = nn::load_vgg19_keras(kWeights);
  const double err = compare_with_opencv(w, "vgg_shared", 40, 56, 7);
  CHECK(err < 1e-4);
}

TEST_CASE("VGG19: a full VGG19 read through OpenCV (Caffe files) gives relu1_2 .. relu5_1 matching OpenCV") {
  const nn::VggWeights w = narrow_vgg19(5);
  const double err = compare_with_opencv(w, "vgg_narrow", 48, 64, 9);
  CHECK(err < 1e-4);

  // The loader path: the files written above, read back through cv::dnn.
  const nn::VggWeights back = nn::load_vgg19_opencv(tmp_path("vgg_narrow.caffemodel"), tmp_path("vgg_narrow.prototxt"),
                                                    nn::VggPreprocess::TorchRGB);
  REQUIRE(back.convs.size() == 16);
  for (int i = 0; i < 16; ++i) {
    CHECK(back.convs[i].weight == w.convs[i].weight);
    CHECK(back.convs[i].bias == w.convs[i].bias);
  }
  nn::VGG19Features<float> vgg(back);
  CHECK(vgg.layer_names() == std::vector<std::string>{"relu1_2", "relu2_1", "relu3_1", "relu4_1", "relu5_1"});
  const auto f = vgg.features(random_image<float>(1, 32, 32, 3));
  CHECK(f[4].shape() == ag::Shape{1, 24, 2, 2});
}

TEST_CASE("VGG19: the shared weights survive the Caffe/OpenCV loader bit-exactly") {
  const nn::VggWeights w = nn::load_vgg19_keras(kWeights);
  const std::string proto = tmp_path("vgg_shared_rt.prototxt"), model = tmp_path("vgg_shared_rt.caffemodel");
  nn::write_vgg_caffe(w, proto, model, 32, 32);
  const nn::VggWeights back = nn::load_vgg19_opencv(model, proto, nn::VggPreprocess::CaffeBGR);
  REQUIRE(back.convs.size() == 8);
  for (int i = 0; i < 8; ++i)
    CHECK(std::memcmp(back.convs[i].weight.data(), w.convs[i].weight.data(), 4 * w.convs[i].weight.size()) == 0);
}

TEST_CASE("VGG19: weights are frozen, gradients reach the image (float64 gradient check of the cosine loss)") {
  nn::VggWeights w = nn::load_vgg19_keras(kWeights);
  w.convs.resize(3);  // up to relu2_1: enough to cover conv, pool and the folded preprocessing
  nn::VGG19Features<double> vgg(w, {"relu1_2", "relu2_1"});
  const ag::Tensord target = random_image<double>(1, 6, 6, 11);
  ag::Tensord pred = random_image<double>(1, 6, 6, 12);
  // Tolerance 1e-6: the loss is smooth except at ReLU kinks; this fixed input keeps every
  // pre-activation far from 0 relative to the step.
  const auto r = ag::gradcheck([&](const std::vector<ag::Tensord>& in) { return nn::vgg_loss(vgg, in[0], target); },
                               {pred}, ag::GradCheckOptions{});
  CHECK_MESSAGE(r.max_rel_error < 1e-6, r.report());

  pred.set_requires_grad(true);
  pred.zero_grad();
  nn::vgg_loss(vgg, pred, target, nn::FeatureLossKind::L1).backward();
  CHECK(pred.has_grad());
  const ag::Tensord same = pred.detach();
  CHECK(nn::vgg_loss(vgg, same, same).item() == doctest::Approx(0.0).epsilon(1e-12));
}

TEST_CASE("cosine_distance_channels: value, float64 gradient check for both inputs, zero vectors stay finite") {
  nn::Rng rng(21);
  auto rnd = [&](const ag::Shape& s) {
    ag::Tensord t = ag::Tensord::zeros(s);
    for (auto& v : t.values()) v = rng.normal(0, 1);
    return t;
  };
  const ag::Tensord a = rnd({2, 5, 3, 4}), b = rnd({2, 5, 3, 4});
  double sum = 0;
  for (int n = 0; n < 2; ++n)
    for (int p = 0; p < 12; ++p) {
      double ab = 0, aa = 0, bb = 0;
      for (int c = 0; c < 5; ++c) {
        const double x = a.data()[(n * 5 + c) * 12 + p], y = b.data()[(n * 5 + c) * 12 + p];
        ab += x * y;
        aa += x * x;
        bb += y * y;
      }
      sum += ab / std::sqrt(aa * bb);
    }
  CHECK(nn::cosine_distance_channels(a, b).item() == doctest::Approx(1.0 - sum / 24).epsilon(1e-13));
  const auto r = ag::gradcheck(
      [](const std::vector<ag::Tensord>& in) { return nn::cosine_distance_channels(in[0], in[1]); }, {a, b});
  // Tolerance 1e-5: the loss is a mean of 24 cosines of O(1); entries whose gradient is ~1e-4
  // of the largest carry central-difference round-off (~1e-10 absolute) of that order.
  CHECK_MESSAGE(r.max_rel_error < 1e-5, r.report());
  for (double s : {1e-3, 1e3}) {
    // gradcheck's step is relative to the inputs' size: the same options at every scale.
    const ag::GradCheckOptions o;
    const ag::Tensord other = rnd({1, 3, 2, 2});
    const auto rs =
        ag::gradcheck([&](const std::vector<ag::Tensord>& in) { return nn::cosine_distance_channels(in[0], other); },
                      {ag::mul_scalar(rnd({1, 3, 2, 2}), s).detach()}, o);
    CHECK_MESSAGE(rs.max_rel_error < 1e-5, "scale " << s << ": " << rs.report());
  }

  ag::Tensord z = ag::Tensord::zeros({1, 4, 2, 2}, true);
  ag::Tensord c = rnd({1, 4, 2, 2});
  ag::Tensord l = nn::cosine_distance_channels(z, c);
  CHECK(l.item() == 1.0);
  l.backward();
  for (double g : z.grad()) CHECK(std::isfinite(g));
  CHECK_THROWS_AS(nn::cosine_distance_channels(a, rnd({2, 5, 3, 3})), ag::Error);
}

// Module registry, initialisations, Linear / MLP block / complex linear, copy_parameters.
#include "autograd/autograd.hpp"
#include "nn/complex_linear.hpp"
#include "nn/init.hpp"
#include "nn/linear.hpp"
#include "nn/mlp.hpp"

#include <doctest/doctest.h>

#include <cmath>

namespace {
struct Net : nn::Module<double> {
  std::shared_ptr<nn::MLPStack<double>> enc;
  std::shared_ptr<nn::Linear<double>> head;
  ag::Tensord gain;
  Net(nn::Rng& rng) {
    enc = register_module("encoder",
                          std::make_shared<nn::MLPStack<double>>(std::vector<int64_t>{4, 6, 5}, true, true, rng));
    head = register_module("head", std::make_shared<nn::Linear<double>>(5, 2, false, rng));
    gain = register_parameter("gain", ag::Tensord::full({1, 2}, 1.0));
  }
};

std::pair<double, double> min_max(const ag::Storage<double>& v) {
  return {*std::min_element(v.begin(), v.end()), *std::max_element(v.begin(), v.end())};
}
}  // namespace

TEST_CASE("Module: dotted names in registration order, counts, zero_grad, duplicates refused") {
  nn::Rng rng(1);
  Net net(rng);
  std::vector<std::string> names;
  for (auto& [n, t] : net.named_parameters()) {
    names.push_back(n);
    CHECK(t.requires_grad());
  }
  const std::vector<std::string> expected = {"encoder.0.linear1.weight",
                                             "encoder.0.linear1.bias",
                                             "encoder.0.linear2.weight",
                                             "encoder.0.linear2.bias",
                                             "encoder.0.scale",
                                             "encoder.0.shift",
                                             "encoder.1.linear1.weight",
                                             "encoder.1.linear1.bias",
                                             "encoder.1.linear2.weight",
                                             "encoder.1.linear2.bias",
                                             "encoder.1.scale",
                                             "encoder.1.shift",
                                             "head.weight",
                                             "gain"};
  CHECK(names == expected);
  const int64_t count = 2 + (4 * 6 + 6 + 36 + 6 + 12) + (6 * 5 + 5 + 25 + 5 + 10) + 10;
  CHECK(net.num_parameters() == count);

  ag::sum(net.head->forward(net.enc->forward(ag::Tensord::full({3, 4}, 0.5)))).backward();
  CHECK(net.head->weight.has_grad());
  net.zero_grad();
  for (auto& t : net.parameters()) CHECK_FALSE(t.has_grad());

  struct Bad : nn::Module<float> {
    Bad() {
      register_parameter("w", ag::Tensorf::zeros({1, 1}));
      register_parameter("w", ag::Tensorf::zeros({1, 1}));
    }
  };
  CHECK_THROWS_AS(Bad(), ag::Error);
}

TEST_CASE("Linear: PyTorch default init bounds 1/sqrt(in) for weight and bias / forward = x W^T + b") {
  nn::Rng rng(7);
  nn::Linear<double> lin(64, 300, true, rng);
  const double bound = 1.0 / 8.0;
  auto [wlo, whi] = min_max(lin.weight.values());
  CHECK(wlo >= -bound);
  CHECK(whi <= bound);
  CHECK(wlo < -0.95 * bound);  // 19200 draws fill the interval
  CHECK(whi > 0.95 * bound);
  double var = 0;
  for (double v : lin.weight.values()) var += v * v;
  var /= static_cast<double>(lin.weight.numel());
  CHECK(std::abs(var - bound * bound / 3) < 0.05 * bound * bound / 3);  // U(-a, a) variance a^2/3
  auto [blo, bhi] = min_max(lin.bias.values());
  CHECK(blo >= -bound);
  CHECK(bhi <= bound);
  CHECK(bhi - blo > bound);
  CHECK(lin.weight.shape() == ag::Shape{300, 64});
  CHECK(lin.bias.shape() == ag::Shape{1, 300});

  nn::Linear<double> small(3, 2, true, rng);
  const ag::Tensord x = ag::Tensord::from({2, 3}, {1, 2, 3, -1, 0.5, 2});
  const ag::Tensord y = small.forward(x);
  for (int r = 0; r < 2; ++r)
    for (int o = 0; o < 2; ++o) {
      double e = small.bias.values()[o];
      for (int i = 0; i < 3; ++i) e += x.at(r, i) * small.weight.at(o, i);
      CHECK(y.at(r, o) == doctest::Approx(e).epsilon(1e-14));
    }
  CHECK_THROWS_AS(nn::Linear<float>(0, 3, true, rng), ag::Error);
}

TEST_CASE("init: Xavier-uniform and Kaiming bounds") {
  nn::Rng rng(3);
  ag::Tensord t = ag::Tensord::zeros({100, 50});
  nn::xavier_uniform_(t, 50, 100, rng);
  const double xb = std::sqrt(6.0 / 150.0);
  auto [lo, hi] = min_max(t.values());
  CHECK(lo >= -xb);
  CHECK(hi <= xb);
  CHECK(hi > 0.95 * xb);
  nn::kaiming_uniform_(t, 50, 0.0, rng);  // a = 0: bound sqrt(6 / fan_in)
  std::tie(lo, hi) = min_max(t.values());
  CHECK(hi <= std::sqrt(6.0 / 50));
  CHECK(hi > 0.95 * std::sqrt(6.0 / 50));
}

TEST_CASE("MLPBlock: forward matches its definition / float64 gradient check with norm and scale/shift") {
  nn::Rng rng(11);
  nn::MLPBlock<double> blk(3, 4, true, true, rng);
  for (auto& v : blk.scale.values()) v = rng.uniform(-0.5, 0.5);
  for (auto& v : blk.shift.values()) v = rng.uniform(-0.5, 0.5);
  ag::Tensord x = ag::Tensord::zeros({7, 3});
  for (auto& v : x.values()) v = rng.normal(0, 1);

  // Reference with Eigen.
  auto lrelu = [](Eigen::MatrixXd m) { return m.unaryExpr([](double v) { return v > 0 ? v : 0.02 * v; }).eval(); };
  Eigen::MatrixXd h =
      lrelu((x.mat() * blk.linear1->weight.mat().transpose()).rowwise() + blk.linear1->bias.mat().row(0));
  h = (h * blk.linear2->weight.mat().transpose()).rowwise() + blk.linear2->bias.mat().row(0);
  for (int c = 0; c < h.cols(); ++c) {
    const double mu = h.col(c).mean();
    const double var = (h.col(c).array() - mu).square().mean();
    h.col(c) = (h.col(c).array() - mu) / std::sqrt(var + 1e-5);
  }
  for (int c = 0; c < h.cols(); ++c)
    h.col(c) = h.col(c) * (1 + blk.scale.values()[c]) + Eigen::VectorXd::Constant(h.rows(), blk.shift.values()[c]);
  h = lrelu(h);
  CHECK((blk.forward(x).mat() - h).cwiseAbs().maxCoeff() < 1e-12);

  // Gradient with respect to the input and all parameters (tolerance 1e-6: smooth except
  // at the LeakyReLU kinks, which random inputs avoid by a wide margin).
  // linear2.bias is left out: the channel norm removes any per-column shift, so its
  // gradient is exactly 0 and checked as such below.
  std::vector<ag::Tensord> inputs{x};
  for (auto& [n, p] : blk.named_parameters())
    if (n != "linear2.bias") inputs.push_back(p);
  CHECK(inputs.size() == 6);
  // Step 2e-6 of each input's largest entry: the parameters are at most ~0.5, and h = 1e-6 *
  // 0.5 lets round-off of the 28-output loss (~8e-9 on a gradient that is exactly 0) reach
  // 1.6e-6 of the largest bias gradient; at 2e-6 it is half that.
  ag::GradCheckOptions opt;
  opt.step = 2e-6;
  const auto r = ag::gradcheck([&](const std::vector<ag::Tensord>&) { return blk.forward(inputs[0]); }, inputs, opt);
  CHECK_MESSAGE(r.max_rel_error < 1e-6, r.report());
  blk.zero_grad();
  ag::sum(ag::mul(blk.forward(x), blk.forward(x))).backward();
  double gb = 0, gw = 0;
  for (double g : blk.linear2->bias.grad()) gb = std::max(gb, std::abs(g));
  for (double g : blk.linear2->weight.grad()) gw = std::max(gw, std::abs(g));
  CHECK(gb < 1e-12 * gw);
}

TEST_CASE("MLPStack: widths chain, no-norm variant, bad widths refused") {
  nn::Rng rng(5);
  nn::MLPStack<float> s({23, 32, 16, 8}, false, false, rng);
  CHECK(s.blocks.size() == 3);
  CHECK(s.forward(ag::Tensorf::zeros({10, 23})).shape() == ag::Shape{10, 8});
  CHECK(s.num_parameters() == (23 * 32 + 32 + 32 * 32 + 32) + (32 * 16 + 16 + 16 * 16 + 16) + (16 * 8 + 8 + 8 * 8 + 8));
  CHECK_THROWS_AS(nn::MLPStack<float>({4}, false, false, rng), ag::Error);
  CHECK_THROWS_AS(s.forward(ag::Tensorf::zeros({10, 22})), ag::Error);
}

TEST_CASE("ComplexLinear: WIRE init bounds per real/imaginary part, forward = x W^T + b") {
  nn::Rng rng(9);
  nn::ComplexLinear<double> first(3, 400, true, nn::WireInit::First, rng);
  nn::ComplexLinear<double> hidden(64, 64, true, nn::WireInit::Hidden, rng, 5.0);
  auto bounds = [](const ag::Tensorcd& t) {
    double m = 0;
    for (auto z : t.values()) m = std::max({m, std::abs(z.real()), std::abs(z.imag())});
    return m;
  };
  CHECK(bounds(first.weight) <= 1.0 / 3);
  CHECK(bounds(first.weight) > 0.95 / 3);
  const double hb = std::sqrt(6.0 / 64) / 5.0;
  CHECK(bounds(hidden.weight) <= hb);
  CHECK(bounds(hidden.weight) > 0.95 * hb);
  CHECK(bounds(hidden.bias) <= 1.0 / 8);
  bool has_imag = false;
  for (auto z : hidden.weight.values()) has_imag = has_imag || z.imag() != 0;
  CHECK(has_imag);

  const ag::Tensord xr = ag::Tensord::from({2, 3}, {0.1, -0.2, 0.3, 0.5, 0.0, -1.0});
  const ag::Tensorcd y = first.forward_real(xr);
  for (int r = 0; r < 2; ++r)
    for (int o = 0; o < 5; ++o) {
      std::complex<double> e = first.bias.values()[o];
      for (int i = 0; i < 3; ++i) e += xr.at(r, i) * first.weight.at(o, i);
      CHECK(std::abs(y.at(r, o) - e) < 1e-14);
    }
}

TEST_CASE("copy_parameters: float <-> double by name / mismatches refused") {
  nn::Rng r1(1), r2(2);
  nn::MLPStack<double> d({4, 8, 3}, true, true, r1);
  nn::MLPStack<float> f({4, 8, 3}, true, true, r2);
  nn::copy_parameters(d, f);
  auto pd = d.named_parameters();
  auto pf = f.named_parameters();
  for (size_t i = 0; i < pd.size(); ++i)
    for (int64_t k = 0; k < pd[i].second.numel(); ++k)
      CHECK(pf[i].second.values()[k] == static_cast<float>(pd[i].second.values()[k]));
  nn::MLPStack<double> back({4, 8, 3}, true, true, r1);
  nn::copy_parameters(f, back);
  CHECK(back.named_parameters()[0].second.values()[0] == static_cast<double>(pf[0].second.values()[0]));

  nn::MLPStack<float> other({4, 9, 3}, true, true, r2);
  CHECK_THROWS_WITH_AS(nn::copy_parameters(d, other), doctest::Contains("0.linear1.weight"), ag::Error);
  nn::MLPStack<float> fewer({4, 8}, true, true, r2);
  CHECK_THROWS_AS(nn::copy_parameters(d, fewer), ag::Error);

  nn::ComplexLinear<float> cf(3, 2, true, nn::WireInit::PyTorch, r1);
  nn::ComplexLinear<double> cd(3, 2, true, nn::WireInit::PyTorch, r2);
  nn::copy_parameters(cf, cd);
  CHECK(cd.weight.values()[1] == std::complex<double>(cf.weight.values()[1]));
}

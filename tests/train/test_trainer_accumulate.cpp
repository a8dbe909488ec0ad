// Gradient accumulation (--frames-per-step): one optimizer step over K frames, each frame's
// loss backpropagated alone and scaled by 1/K, against the gradient of the averaged K-frame
// loss built in one graph from the public pieces (model, frame input, coarse loss).
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/data/frame_input.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "nn/adamw.hpp"
#include "nn/checkpoint.hpp"
#include "tests/support/data_fixtures.hpp"
#include "train/trainer.hpp"

#include <cmath>

TEST_CASE("trainer: two frames per step equal the gradient of their averaged loss") {
  const gdsr::Dataset d = gdsr_test::wave_dataset(4);  // training frames t = 2, 3: one step
  gdsr_test::TempDir dir("trainer_accumulate");
  gdsr::TrainOptions o;
  o.model = gdsr::load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
  o.model.noise_std = 0;  // the reference below draws no noise
  o.fine = false;         // no patches: nothing random but the frame order, which a sum ignores
  o.frames_per_step = 2;
  o.epochs = 1;
  o.lr = 1e-3;
  o.checkpoint = dir / "model.ckpt";
  double grad_norm = 0, loss = 0;
  int steps = 0;
  gdsr::train_gdsr({&d}, o, [&](const gdsr::TrainLog& L) {
    grad_norm = L.grad_norm;
    loss = L.loss;
    ++steps;
  });
  REQUIRE(steps == 1);

  gdsr::GDSR<float> model(o.model);
  const gdsr::GarmentGraph graph = gdsr::build_graph(d.lr);
  const gdsr::MeshTopology topo = gdsr::make_topology(d.lr);
  std::vector<gdsr::Points3> truth;
  for (const auto& g : d.hr_frames) truth.push_back(gdsr::downsample(d.corr, g));
  const auto body = gdsr::make_body_query(d);
  const gdsr::Lambdas lambdas = gdsr::lambda_schedule(o.loss, 0);
  ag::Tensorf sum;
  for (int t : {2, 3}) {
    const gdsr::FrameInput in = gdsr::make_frame_input(d, t, truth[t - 1], truth[t - 2], body.get());
    const auto out = model.forward(graph, in, nullptr, nullptr);
    const auto c = gdsr::coarse_loss(o.loss, topo, out.C_hat, truth[t]);
    const ag::Tensorf l = gdsr::total_loss(lambdas, c.total, ag::Tensorf());
    sum = sum.defined() ? sum + l : l;
  }
  const ag::Tensorf mean = sum * 0.5f;
  nn::AdamWOptions ao;
  ao.lr = o.lr;
  ao.weight_decay = o.weight_decay;
  ao.amsgrad = o.amsgrad;
  nn::AdamW<float> adam(model.named_parameters(), ao);
  adam.zero_grad();
  mean.backward();
  double norm2 = 0;
  for (const auto& [name, p] : model.named_parameters())
    for (float g : p.grad()) norm2 += static_cast<double>(g) * g;
  // Float sums in another order: relative 1e-5.
  CHECK(loss == doctest::Approx(mean.item()).epsilon(1e-6));
  CHECK(grad_norm == doctest::Approx(std::sqrt(norm2)).epsilon(1e-5));
  REQUIRE(grad_norm > 0);

  // The step itself: the same AdamW update from the one-graph gradient gives the trained
  // parameters up to float rounding of the gradient. AdamW's first step is lr * g / (|g| + eps),
  // which is ill-conditioned where |g| is near eps (1e-8): a rounding-size change of such a
  // g moves the parameter by up to lr. Those entries are compared with the bound lr instead
  // (and counted; about half of the tiny preset's entries, mostly A's, which the coarse loss
  // alone barely reaches); every other entry must agree to 1e-3 lr.
  std::vector<std::vector<float>> grads;
  for (const auto& [name, p] : model.named_parameters())
    grads.push_back(p.has_grad() ? ag::to_vector(p.grad()) : std::vector<float>(p.numel(), 0.f));
  adam.step();
  gdsr::GDSR<float> trained(o.model);
  nn::load_checkpoint<float>(o.checkpoint, trained, nullptr);
  const auto a = model.named_parameters(), b = trained.named_parameters();
  REQUIRE(a.size() == b.size());
  double worst = 0, worst_small = 0;
  long small = 0, total = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int64_t k = 0; k < a[i].second.numel(); ++k) {
      const double diff = std::abs(static_cast<double>(a[i].second.data()[k]) - b[i].second.data()[k]);
      ++total;
      if (std::abs(grads[i][k]) < 1e-6) {
        ++small;
        worst_small = std::max(worst_small, diff);
      } else {
        worst = std::max(worst, diff);
      }
    }
  MESSAGE("largest parameter difference after one step: " << worst << " (lr " << o.lr << "); " << small << " of "
                                                          << total << " entries with |g| < 1e-6 differ by up to "
                                                          << worst_small);
  CHECK(worst < 1e-3 * o.lr);
  CHECK(worst_small <= 2.0001 * o.lr);
}

// Whole-model gradient check in float64 at the tiny preset: features -> H -> E -> A -> field
// -> G on a two-layer 3x3-grid garment (so the layer-edge MLPs take part) with a plane
// body close enough for the body interaction to be active at some vertices. Inputs
// checked: every parameter tensor of the model and the LR positions C_t. Also in units of
// 1e3 and 1e-3 metre (the model converted as in test_model_invariance.cpp): same tolerance.
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_config.hpp"
#include "tests/support/ag_test_util.hpp"
#include "tests/support/body_contact.hpp"
#include "tests/support/model_test_util.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

using namespace gdsr;

namespace {

// The tiny model on a two-layer 3 x 3 garment 1 cm above the plane y = 0, one frame of input.
struct Setup {
  ModelConfig cfg = load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
  GDSR<double> model{cfg};
  GarmentMesh garment = gdsr_test::two_layer_garment(3, 0.1, 0.01);
  GarmentGraph g = build_graph(garment);
  nn::Rng rng{11};
  FrameInput in = make_input();
  FrameInput make_input() {
    Points3 rest = garment.V;
    rest.col(1).array() += 0.01;
    return gdsr_test::make_frame(rest, rng, 0.002);
  }
};

}  // namespace

namespace {

enum class Units {
  converted,  // the model converted to units of s metres (gdsr_test::model_in_units)
  raw         // the metre model given positions x s (a garment in the wrong units)
};

// The whole-model check with the graph, frame and positions scaled by s. Converted, the
// relative errors must be those at s = 1 (steps are relative to each input's largest entry);
// the absolute floor below which gradients are judged by their absolute error scales with
// them (a parameter of unit power p gets s^(1 - p) x its gradient in metres). Raw, the model
// meets features 1e3 x larger or smaller than in training: its gradients must still be right.
void check_whole_model(double s, Units units) {
  const bool convert = units == Units::converted;
  Setup S;
  // E's bias starts at 0, where gradcheck's step falls back to an absolute 1e-5 (no scale to
  // be relative to), which is not the same step in other units: give it a size in metres.
  S.model.e().bias.values() = {0.02, -0.03, 0.01};
  const std::unique_ptr<GDSR<double>> converted = gdsr_test::model_in_units(S.model, s);
  GDSR<double>& model = convert ? *converted : S.model;
  GarmentMesh rest = S.garment;
  rest.V *= s;
  const GarmentGraph g = build_graph(rest);
  nn::Rng& rng = S.rng;
  FrameInput in = gdsr_test::frame_in_units(S.in, s);
  // No body here: with the plane body the central differences through H do not converge at
  // this graph size (worst relative error 2.0 / 0.87 / 0.037 at steps 1e-5 / 1e-6 / 1e-7: a
  // strongly curved spot of the normalised tiny H, not a wrong gradient). The body
  // interaction's gradient with respect to C is checked in the next test case.
  in.has_body = false;
  const HrRequest hr = gdsr_test::random_samples(g.num_faces(), 12, rng);

  // Some tensors get an exactly zero gradient by construction (biases right before a
  // per-channel normalisation, e.g. linear2.bias of H's normed blocks): their central
  // differences are pure round-off, which gradcheck's per-input relative floor cannot
  // judge. They are found by a first backward and checked separately to have a numeric
  // gradient at round-off level.
  ag::Tensord C = ag::Tensord::from_eigen(in.C_t, true);
  auto f = [&](const std::vector<ag::Tensord>& x) {
    // Parameters are the model's own tensors (perturbed in place by gradcheck).
    const auto out = model.forward(g, x.back(), in, &hr);
    // (raw: at x1e3 the layers are beyond sigma_l, at x1e-3 every pair is a layer edge)
    if (convert) REQUIRE(out.features.layer_edges.size() > 0);
    return ag::concat_rows<double>({out.C_hat, out.G});
  };
  ag::sum(f({C})).backward();
  // Converted gradients in metres' terms: divided by s^(1 - p) (p: unit power of the tensor;
  // mixed only in h.node_pre.0.linear1.weight, whose metric columns dominate its gradient).
  auto metre_factor = [&](const std::string& name) {
    return convert ? std::pow(s, 1 - gdsr_test::unit_power(name, 3)) : 1.0;
  };
  double largest_all = 0;
  for (const auto& [name, t] : model.named_parameters())
    if (t.has_grad())
      for (double v : t.grad()) largest_all = std::max(largest_all, std::abs(v) / metre_factor(name));
  // Grouped by unit power: each group's absolute floor in its own units.
  std::map<int, std::vector<ag::Tensord>> inputs;
  std::vector<std::pair<std::string, ag::Tensord>> zero_grad;
  std::string zero_names;
  size_t num_params = 0;
  for (const auto& [name, t] : model.named_parameters()) {
    double m = 0;
    if (t.has_grad())
      for (double v : t.grad()) m = std::max(m, std::abs(v) / metre_factor(name));
    if (m < 1e-10 * largest_all) {
      zero_grad.push_back({name, t});
      zero_names += name + " ";
    } else {
      inputs[gdsr_test::unit_power(name, 3)].push_back(t);
      ++num_params;
    }
  }
  model.zero_grad();
  C.zero_grad();
  MESSAGE("x" << s << ": zero-gradient tensors: " << zero_names);
  for (const auto& [name, t] : zero_grad) {
    const auto r = ag::gradcheck([&](const std::vector<ag::Tensord>&) { return f({C}); }, {t});
    CHECK(std::abs(r.numeric) < 1e-8 * largest_all * metre_factor(name));
  }
  ag::GradCheckOptions opt;
  opt.max_entries_per_input = 60;
  // Step 1e-5 of each parameter tensor's largest entry (most are ~0.3, so h ~ 3e-6): the
  // worst error here is round-off, not truncation. With -march=native (FMA) it measured
  // 6.2e-5 / 1.1e-5 / 9.0e-6 / 2.9e-6 at absolute steps 3e-7 / 1e-6 / 2e-6 / 4e-6, falling as
  // 1/step; the x86-64-v2 build gave 8.1e-6 at 1e-6. Hence the tolerance 1e-5, not 1e-6.
  opt.step = 1e-5;
  int64_t checked = 0;
  for (const auto& [p, group] : inputs) {
    CAPTURE(p);
    // Entries below 1e-3 (in metres' terms) are judged by absolute error: the loss sums 117
    // outputs, and its central differences carry round-off near 1e-8 (seen: analytic -1.8e-13
    // vs numeric -8.1e-9 on a parameter whose other gradients are ~1e-1). Raw, that round-off
    // grows with the outputs' size, max(E's ~0.1 m, s x the garment): 1e-3 x max(1, s) (at
    // x1e3 a floor of 1e-3 fails at 5.8e-5 on entries of 4e-5, round-off).
    opt.abs_floor = convert ? 1e-3 * std::pow(s, 1 - p) : 1e-3 * std::max(1.0, s);
    // h.node_pre.0.linear1.weight has unit-free columns (the normal) next to metric ones: in
    // other units their sizes differ by s, so each column gets its own step.
    opt.per_column = p == -1;
    const ag::GradCheckResult r =
        ag::gradcheck([&](const std::vector<ag::Tensord>&) { return f({C}); }, group, opt);
    MESSAGE("x" << s << ", parameters of unit power " << p << ": " << r.report());
    CHECK(r.max_rel_error < 1e-5);
    checked += r.checked;
  }
  MESSAGE("x" << s << ": parameters: " << model.num_parameters() << " in " << num_params << " tensors; checked "
              << checked << " entries");
  CHECK(checked > 500);
  // With respect to C the step must be 1e-7 of the largest |C| (tolerance unchanged): the
  // worst relative error falls 1.25 -> 0.22 -> 8e-3 -> 2e-7 for absolute steps 1e-4 -> 1e-5 ->
  // 1e-6 -> 1e-7 (and is 2e-6 at 1e-8, round-off): truncation error of the strongly curved
  // normalised features of a 10 cm garment (channel norm over 18 vertices), not a wrong
  // gradient. d(outputs)/dC is unit-free: the floor stays 1e-3 (raw too).
  ag::GradCheckOptions opt_c = opt;
  opt_c.step = 1e-7;
  opt_c.abs_floor = 1e-3;
  const ag::GradCheckResult rc = ag::gradcheck(f, {C}, opt_c);
  MESSAGE("x" << s << ": input positions C: " << rc.report());
  CHECK(rc.max_rel_error < 1e-5);
}

}  // namespace

TEST_CASE("model gradcheck: whole GDSR model, tiny preset, float64") {
  // Parameters and C; the body-interaction features are off here (see check_whole_model).
  check_whole_model(1.0, Units::converted);
}

TEST_CASE("model gradcheck: whole GDSR model in mm and km units (positions x1e3 and x1e-3)") {
  check_whole_model(1e3, Units::converted);
  check_whole_model(1e-3, Units::converted);
}

TEST_CASE("model gradcheck: the metre model on positions x1e3 and x1e-3 without conversion") {
  check_whole_model(1e3, Units::raw);
  check_whole_model(1e-3, Units::raw);
}

// The same check piece by piece with respect to C only (localises a failure).
TEST_CASE("model gradcheck: pieces with respect to C (features, E, A, upsampling)") {
  Setup S;
  const ModelConfig& cfg = S.cfg;
  GDSR<double>& model = S.model;
  const GarmentGraph& g = S.g;
  nn::Rng& rng = S.rng;
  FrameInput& in = S.in;
  const TriMesh body = gdsr_test::plane_body(0.0);
  in.has_body = true;
  in.contact_t = gdsr_test::closest_points_bruteforce(body, in.C_t);
  in.contact_tm1 = gdsr_test::closest_points_bruteforce(body, in.C_tm1);
  const HrRequest hr = gdsr_test::random_samples(g.num_faces(), 12, rng);
  ag::Tensord z = ag::Tensord::zeros({g.num_vertices, cfg.decoder.back()});
  for (double& v : z.values()) v = rng.normal(0, 1);

  auto check = [&](const char* name, const std::function<ag::Tensord(const ag::Tensord&)>& fn) {
    ag::Tensord C = ag::Tensord::from_eigen(in.C_t, true);
    const auto r = ag::gradcheck([&](const std::vector<ag::Tensord>& x) { return fn(x[0]); }, {C});
    MESSAGE(std::string(name) << ": " << r.report());
    CHECK(r.max_rel_error < 1e-5);
  };
  check("node features", [&](const ag::Tensord& C) { return compute_features(g, C, in, cfg).node; });
  check("ring-1 features", [&](const ag::Tensord& C) { return compute_features(g, C, in, cfg).ring1; });
  check("layer features", [&](const ag::Tensord& C) { return compute_features(g, C, in, cfg).layer; });
  {
    // H with respect to its input features (leaves).
    FrameInput no_body = in;  // see the note in the whole-model check
    no_body.has_body = false;
    const auto f0 = compute_features(g, ag::Tensord::from_eigen(in.C_t), no_body, cfg);
    // One check per feature tensor, each with its own step (relative to its largest entry):
    // the node features reach ~50 and need 1e-6 (truncation: 1.8e-4 at 4e-6), the small
    // layer features 4e-6 (round-off: 1.2e-5 at 1e-6).
    for (int k = 0; k < 3; ++k) {
      CAPTURE(k);
      ag::GradCheckOptions opt;
      opt.step = k == 2 ? 4e-6 : 1e-6;
      const ag::Tensord feat = (k == 0 ? f0.node : k == 1 ? f0.ring1 : f0.layer).detach();
      const auto r = ag::gradcheck(
          [&](const std::vector<ag::Tensord>& x) {
            GraphFeatures<double> f = f0;
            (k == 0 ? f.node : k == 1 ? f.ring1 : f.layer) = x[0];
            return model.h().forward(g, f);
          },
          {feat}, opt);
      MESSAGE("H w.r.t. features " << k << ": " << r.report());
      CHECK(r.max_rel_error < 1e-5);
    }
  }
  check("E: C_hat for fixed z", [&](const ag::Tensord& C) { return model.decode(g, C, z, nullptr).C_hat; });
  check("A: residual for fixed z", [&](const ag::Tensord& C) { return model.decode(g, C, z, &hr).residual; });
  check("upsampled C_hat for fixed z", [&](const ag::Tensord& C) { return model.decode(g, C, z, &hr).upsampled; });
}

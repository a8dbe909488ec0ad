// Whole-model gradient check in float64 at the tiny preset: features -> H -> E -> A -> field
// -> G on a two-layer 3x3-grid garment (so the layer-edge MLPs take part) with a plane
// body close enough for the body interaction to be active at some vertices. Inputs
// checked: every parameter tensor of the model and the LR positions C_t.
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/gdsr_model.hpp"
#include "gdsr/model_config.hpp"
#include "model_test_util.hpp"

#include <string>

using namespace gdsr;

TEST_CASE("model gradcheck: whole GDSR model, tiny preset, float64") {
  const ModelConfig cfg = load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
  GDSR<double> model(cfg);
  const GarmentMesh garment = gdsr_test::two_layer_garment(3, 0.1, 0.01);
  const GarmentGraph g = build_graph(garment);
  nn::Rng rng(11);
  // Lift everything so the lower layer is ~0.01 above the plane y = 0 (m > 0 there) and
  // the upper layer ~0.02 above it (m = 0): both branches of the ReLU are exercised.
  Points3 rest = garment.V;
  rest.col(1).array() += 0.01;
  FrameInput in = gdsr_test::make_frame(rest, rng, 0.002);
  const TriMesh body = gdsr_test::plane_body(0.0);
  in.has_body = true;
  in.contact_t = closest_points_bruteforce(body, in.C_t);
  in.contact_tm1 = closest_points_bruteforce(body, in.C_tm1);
  const HrRequest hr = gdsr_test::random_samples(g.num_faces(), 12, rng);

  std::vector<ag::Tensord> inputs = model.parameters();
  const size_t num_params = inputs.size();
  ag::Tensord C = ag::Tensord::from_eigen(in.C_t, true);
  inputs.push_back(C);

  auto f = [&](const std::vector<ag::Tensord>& x) {
    // Parameters are the model's own tensors (perturbed in place by gradcheck).
    const auto out = model.forward(g, x.back(), in, &hr);
    REQUIRE(out.features.layer_edges.size() > 0);
    return ag::concat_rows<double>({out.C_hat, out.G});
  };
  ag::GradCheckOptions opt;
  opt.max_entries_per_input = 60;
  const ag::GradCheckResult r = ag::gradcheck(f, inputs, opt);
  MESSAGE("parameters: " << model.num_parameters() << " in " << num_params << " tensors; checked "
                         << r.checked << " entries; " << r.report());
  CHECK(r.max_rel_error < 1e-5);
  CHECK(r.checked > 500);
}

#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "train/losses.hpp"
#include "tests/support/loss_test_meshes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

using namespace gdsr;

namespace {

bool finite(const ag::Storage<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

LossConfig only(const std::string& term) {
  LossConfig c;
  for (LossTerm* t : {&c.c_position, &c.c_normal, &c.c_strain, &c.c_smooth, &c.c_dihedral, &c.f_position,
                      &c.f_normal_map, &c.f_strain, &c.f_smooth})
    t->on = false;
  if (term == "c_position") c.c_position.on = true;
  if (term == "c_normal") c.c_normal.on = true;
  if (term == "c_strain") c.c_strain.on = true;
  if (term == "c_smooth") c.c_smooth.on = true;
  if (term == "c_dihedral") c.c_dihedral.on = true;
  if (term == "f_position") c.f_position.on = true;
  if (term == "f_vgg") c.f_normal_map.on = true, c.f_image_l1.on = false;
  if (term == "f_image_l1") c.f_normal_map.on = true, c.f_vgg.on = false;
  if (term == "f_strain") c.f_strain.on = true;
  if (term == "f_smooth") c.f_smooth.on = true;
  return c;
}

ag::Tensord rows_of(const Points3& P, const std::vector<int>& rows) {
  Points3 R(static_cast<int>(rows.size()), 3);
  for (size_t i = 0; i < rows.size(); ++i) R.row(static_cast<int>(i)) = P.row(rows[i]);
  return to_tensor<double>(R);
}

// A 5 x 5 grid (5 cm) with a ground truth and a prediction, and the corners a, b, c of its
// interior face f0 (made degenerate by the tests).
struct GridPrediction {
  GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec::spaced(5, 0.05));
  MeshTopology t = make_topology(g);
  Points3 gt = gdsr_test::bumpy(g.V, 0.2, 1.0, 1);
  Points3 base = gdsr_test::bumpy(g.V, 0.2, 1.0, 2);
  int f0 = 12;
  int a = g.F(f0, 0), b = g.F(f0, 1), c = g.F(f0, 2);
};

}  // namespace

TEST_CASE("losses: config defaults follow the reference, JSON round trip, unknown keys throw") {
  const LossConfig d;
  CHECK(d.c_position.weight == 1.0);
  CHECK(d.c_normal.weight == 0.01);
  CHECK(d.c_strain.weight == 0.01);
  CHECK(d.c_smooth.weight == 100.0);
  CHECK(d.c_dihedral.weight == 0.003);
  CHECK(d.f_normal_map.weight == 0.01);
  CHECK(d.f_strain.weight == 0.01);
  CHECK(d.f_smooth.weight == 0.05);
  LossConfig c;
  c.c_dihedral = {false, 0.5};
  c.f_vgg.weight = 2;
  c.image_l1_garment_only = true;
  c.lambda_every_epochs = 3;
  const LossConfig r = loss_config_from_json(loss_config_to_json(c));
  CHECK(r.c_dihedral.on == false);
  CHECK(r.c_dihedral.weight == 0.5);
  CHECK(r.f_vgg.weight == 2);
  CHECK(r.image_l1_garment_only);
  CHECK(r.lambda_every_epochs == 3);
  CHECK(loss_config_to_json(r) == loss_config_to_json(c));
  CHECK_THROWS(loss_config_from_json(nlohmann::json::parse(R"({"coarse": {"positon": {"on": true}}})")));
  CHECK_THROWS(loss_config_from_json(nlohmann::json::parse(R"({"coarse": {"normal": {"weight": -1}}})")));
  CHECK_THROWS(loss_config_from_json(nlohmann::json::parse(R"({"fine": {"smooth": {"on": 3.5}}})")));
  const LossConfig p = loss_config_from_json(nlohmann::json::parse(R"({"fine": {"vgg": {"on": false}}})"));
  CHECK(!p.f_vgg.on);
  CHECK(p.c_smooth.weight == 100.0);

  const std::string path = std::string(GDSR_BINARY_DIR) + "/test_loss_config.json";
  {
    std::ofstream o(path);
    o << R"({"schedule": {"on": false}})";
  }
  CHECK(!load_loss_config(path).schedule);
  std::remove(path.c_str());
  CHECK_THROWS(load_loss_config(path));
}

TEST_CASE("losses: lambda schedule moves by 0.2 every 10 epochs until both are 1") {
  const LossConfig c;
  const double expect_c[] = {1.9, 1.7, 1.5, 1.3, 1.1, 1.0, 1.0};
  for (int k = 0; k < 7; ++k) {
    for (int e : {10 * k, 10 * k + 9}) {
      CAPTURE(e);
      const Lambdas l = lambda_schedule(c, e);
      CHECK(l.coarse == doctest::Approx(expect_c[k]));
      CHECK(l.fine == doctest::Approx(std::min(1.0, 0.1 + 0.2 * k)));
    }
  }
  CHECK(lambda_schedule(c, 300).coarse == 1.0);
  CHECK(lambda_schedule(c, 300).fine == 1.0);
  LossConfig off;
  off.schedule = false;
  CHECK(lambda_schedule(off, 0).coarse == 1.0);
  CHECK(lambda_schedule(off, 0).fine == 1.0);
  const ag::Tensord t = total_loss(Lambdas{1.9, 0.1}, ag::Tensord::scalar(2.0), ag::Tensord::scalar(3.0));
  CHECK(t.item() == doctest::Approx(1.9 * 2 + 0.1 * 3));
}

TEST_CASE("losses: coarse terms vanish at the ground truth and pass float64 gradient checks") {
  const GarmentMesh g0 = gdsr_test::grid_garment(gdsr_test::GridSpec::spaced(5, 0.03));
  for (double scale : {1.0, 1e-3, 1e3}) {
    CAPTURE(scale);
    GarmentMesh g = g0;
    g.V *= scale;
    g.UV *= scale;
    const MeshTopology t = make_topology(g);
    // x1e3: also moved to x ~ +1000 (uniform gradcheck step, see test_geometry_ad).
    const double offset = scale > 1 ? 1000.0 : 0.0;
    const Points3 gt = gdsr_test::bumpy(g0.V, 0.4, scale, 1).array() + offset;
    const Points3 pred = gdsr_test::bumpy(g0.V, 0.3, scale, 2).array() + offset;

    const CoarseLoss<double> same = coarse_loss(LossConfig{}, t, to_tensor<double>(gt), gt);
    CHECK(same.position == 0.0);
    CHECK(same.normal == 0.0);
    CHECK(same.strain == 0.0);
    CHECK(same.dihedral == 0.0);
    CHECK(same.smooth > 0.0);
    CHECK(same.total.item() == doctest::Approx(100.0 * same.smooth));

    const CoarseLoss<double> all = coarse_loss(LossConfig{}, t, to_tensor<double>(pred), gt);
    CHECK(all.position > 0);
    CHECK(all.normal > 0);
    CHECK(all.strain > 0);
    CHECK(all.dihedral > 0);
    CHECK(all.total.item() == doctest::Approx(all.position + 0.01 * all.normal + 0.01 * all.strain + 100 * all.smooth +
                                              0.003 * all.dihedral));
    const CoarseLoss<float> allf = coarse_loss(LossConfig{}, t, to_tensor<float>(pred), gt);
    CHECK(allf.total.item() == doctest::Approx(all.total.item()).epsilon(1e-4));

    for (const char* term : {"c_position", "c_normal", "c_strain", "c_smooth", "c_dihedral"}) {
      INFO(term);
      const LossConfig cfg = only(term);
      ag::GradCheckOptions opt;
      opt.step = scale <= 1 ? 1e-6 : 1e-7;  // h ~ 1e-6 of the mesh size (see test_geometry_ad)
      const ag::GradCheckResult r =
          ag::gradcheck([&](const std::vector<ag::Tensord>& in) { return coarse_loss(cfg, t, in[0], gt).total; },
                        {to_tensor<double>(pred)}, opt);
      INFO(r.report());
      CHECK(r.max_rel_error < 1e-6);
    }
  }
}

TEST_CASE("losses: coarse loss is finite with zero-area triangles") {
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec::spaced(4, 0.05));
  const MeshTopology t = make_topology(g);
  const Points3 gt = gdsr_test::bumpy(g.V, 0.2, 1.0, 1);
  Points3 pred = gdsr_test::bumpy(g.V, 0.2, 1.0, 2);
  pred.row(g.F(0, 1)) = pred.row(g.F(0, 0));  // face 0 collapses to a segment, then a point
  pred.row(g.F(0, 2)) = pred.row(g.F(0, 0));
  ag::Tensord x = to_tensor<double>(pred);
  x.set_requires_grad(true);
  const CoarseLoss<double> l = coarse_loss(LossConfig{}, t, x, gt);
  CHECK(std::isfinite(l.total.item()));
  l.total.backward();
  REQUIRE(x.has_grad());
  CHECK(finite(x.grad()));
}

TEST_CASE("losses: fine loss over a patch batch, with an image-loss callback, float64 gradient check") {
  const GarmentMesh g = gdsr_test::cut_garment(21, 0.01);
  PatchConfig pc;
  pc.size = 24;
  pc.count = 3;
  std::vector<int> lr(g.V.rows(), 0);
  const PatchSampler s(rasterize_uv(g.UV, g.FUV, 128, 128, 4), g, lr, pc);
  std::mt19937_64 rng(11);
  const PatchBatch b = s.sample(rng);
  REQUIRE(b.patches.size() == 3);
  const Points3 gt = gdsr_test::bumpy(g.V, 0.3, 1.0, 1);
  const Points3 pred = gdsr_test::bumpy(g.V, 0.25, 1.0, 2);

  int calls = 0;
  const ImageLossFn<double> mse = [&](const ag::Tensord& a, const ag::Tensord& bb) {
    ++calls;
    CHECK(a.shape() == ag::Shape{3, 3, 24, 24});
    CHECK(bb.shape() == a.shape());
    return ag::mse_loss(ag::reshape(a, {3, 3 * 24 * 24}), ag::reshape(bb, {3, 3 * 24 * 24}));
  };
  const FineLoss<double> same = fine_loss(LossConfig{}, b, rows_of(gt, b.vertices), gt, mse);
  CHECK(calls == 1);
  CHECK(same.position == 0.0);
  CHECK(same.image_l1 == 0.0);
  CHECK(same.vgg == 0.0);
  CHECK(same.strain == 0.0);
  CHECK(same.smooth > 0.0);
  const FineLoss<double> all = fine_loss(LossConfig{}, b, rows_of(pred, b.vertices), gt, mse);
  CHECK(all.position > 0);
  CHECK(all.image_l1 > 0);
  CHECK(all.vgg > 0);
  CHECK(all.strain > 0);
  CHECK(all.total.item() ==
        doctest::Approx(all.position + 0.01 * (all.vgg + all.image_l1) + 0.01 * all.strain + 0.05 * all.smooth));
  LossConfig masked;
  masked.image_l1_garment_only = true;
  const FineLoss<double> m = fine_loss(masked, b, rows_of(pred, b.vertices), gt, mse);
  CHECK(m.image_l1 > all.image_l1);  // same differences, fewer pixels in the mean
  // No callback: the VGG term is skipped.
  CHECK(fine_loss(LossConfig{}, b, rows_of(pred, b.vertices), gt).vgg == 0.0);

  for (const char* term : {"f_position", "f_vgg", "f_image_l1", "f_strain", "f_smooth"}) {
    CAPTURE(term);
    const LossConfig cfg = only(term);
    // Step 4e-6 of the largest |x| (~0.25 m, so h ~ 1e-6): at 1e-6 (h ~ 2.5e-7) round-off on
    // the smallest gradient entries reaches 1.1e-6.
    ag::GradCheckOptions opt;
    opt.step = 4e-6;
    const ag::GradCheckResult r =
        ag::gradcheck([&](const std::vector<ag::Tensord>& in) { return fine_loss(cfg, b, in[0], gt, mse).total; },
                      {rows_of(pred, b.vertices)}, opt);
    INFO(r.report());
    CHECK(r.max_rel_error < 1e-6);
  }
  const FineLoss<float> f = fine_loss<float>(LossConfig{}, b, to_tensor<float>(rows_of(pred, b.vertices).mat()), gt);
  CHECK(f.total.item() ==
        doctest::Approx(fine_loss(LossConfig{}, b, rows_of(pred, b.vertices), gt).total.item()).epsilon(1e-4));
}

TEST_CASE("losses: a predicted sliver's dihedral gradient stays bounded as its height goes to 0") {
  // The dihedral angle's gradient is 1 / height on a sliver; the fade weight (min(1, |cross| /
  // dihedral_floor) per face) caps it at ~ (1 + pi) edge / dihedral_floor, independent of the
  // height. Unweighted, 1e-12 m would give 1000x 1e-9 m's.
  const GridPrediction m;
  const MeshTopology& t = m.t;
  const Points3 &gt = m.gt, &base = m.base;
  const int f0 = m.f0, a = m.a, b = m.b, c = m.c;
  const LossConfig cfg = only("c_dihedral");
  auto sliver_gradient = [&](double h, double* healthy) {
    ag::Tensord x = to_tensor<double>(gdsr_test::sliver(base, a, b, c, h));
    x.set_requires_grad(true);
    coarse_loss(cfg, t, x, gt).total.backward();
    REQUIRE(finite(x.grad()));
    double worst = 0, rest = 0;
    for (int i = 0; i < t.num_vertices; ++i)
      for (int k = 0; k < 3; ++k) {
        const double v = std::abs(x.grad()[3 * i + k]);
        if (i == a || i == b || i == c)
          worst = std::max(worst, v);
        else
          rest = std::max(rest, v);
      }
    if (healthy) *healthy = rest;
    return worst;
  };
  double healthy = 0;
  const double g9 = sliver_gradient(1e-9, &healthy), g12 = sliver_gradient(1e-12, nullptr);
  MESSAGE("dihedral gradient on a sliver: " << g9 << " at 1e-9 m, " << g12 << " at 1e-12 m; healthy max " << healthy);
  CHECK(g12 < 2 * g9);
  CHECK(sliver_gradient(0.0, nullptr) < 2 * g9);
  // (1 + pi) edge / dihedral_floor (the loss is a mean over pairs: less)
  CHECK(g9 < (1 + 3.1415926535897932) * 0.05 / t.dihedral_floor[f0]);
}

TEST_CASE("losses: the dihedral weighting leaves healthy meshes unchanged") {
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec::spaced(5, 0.05));
  const MeshTopology t = make_topology(g);
  const Points3 gt = gdsr_test::bumpy(g.V, 0.2, 1.0, 1), pred = gdsr_test::bumpy(g.V, 0.3, 1.0, 2);
  const CoarseLoss<double> l = coarse_loss(only("c_dihedral"), t, to_tensor<double>(pred), gt);
  const ag::Tensord plain =
      ag::l1_loss(dihedral_angles(to_tensor<double>(pred), t), dihedral_angles(to_tensor<double>(gt), t));
  CHECK(l.dihedral == doctest::Approx(plain.item()).epsilon(1e-14));
}

TEST_CASE("losses: one degenerate triangle cannot dominate a training step") {
  // The whole coarse loss (reference weights) of a 5 x 5 grid prediction (5 cm spacing) with
  // one interior triangle made degenerate. Per-vertex gradient norms |dL/dx_v| at the
  // degenerate triangle's corners must stay within 100 x the median over the vertices of the
  // healthy prediction. Before: a 1e-9 m sliver or a zero-area face gave ~7e4 x (dihedral
  // term, angle gradient 1 / height), coincident vertices or a face collapsed to a point ~1e5 x
  // (shear of the strain term, 1 / max(|F_v|, 1e-6)). Now: 8-9 x and 11-12 x.
  const GridPrediction m;
  const MeshTopology& t = m.t;
  const Points3 &gt = m.gt, &base = m.base;
  const int a = m.a, b = m.b, c = m.c;
  auto vertex_gradients = [&](const Points3& pred, const LossConfig& cfg) {
    ag::Tensord x = to_tensor<double>(pred);
    x.set_requires_grad(true);
    coarse_loss(cfg, t, x, gt).total.backward();
    REQUIRE(finite(x.grad()));
    return gdsr_test::vertex_norms(x.grad());
  };
  const double median = gdsr_test::median(vertex_gradients(base, LossConfig{}));
  REQUIRE(median > 0);
  std::vector<gdsr_test::DegenerateCase> cases = gdsr_test::degenerate_cases(base, a, b, c);
  cases.push_back({"sliver of 1e-5 m", gdsr_test::sliver(base, a, b, c, 1e-5)});
  for (const gdsr_test::DegenerateCase& dc : cases) {
    const std::string& name = dc.name;
    const Points3& pred = dc.P;
    INFO(name);
    const std::vector<double> n = vertex_gradients(pred, LossConfig{});
    const double worst = std::max({n[a], n[b], n[c]});
    std::string terms;  // per-term contribution, to find the culprit when this fails
    for (const char* term : {"c_position", "c_normal", "c_strain", "c_smooth", "c_dihedral"}) {
      LossConfig one = only(term);
      const std::vector<double> m = vertex_gradients(pred, one);
      terms += std::string(" ") + term + " " + std::to_string(std::max({m[a], m[b], m[c]}) / median);
    }
    MESSAGE(name << ": " << worst / median << " x the healthy median;" << terms);
    CHECK(worst < 100 * median);
  }
}

TEST_CASE("losses: the degenerate-face bounds leave healthy faces' values and gradients unchanged") {
  // On a healthy prediction the coarse loss equals, value and gradient, the reference's
  // formulas: shear with normalize eps 1e-6 and the plain (unweighted) L1 of dihedral angles.
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec::spaced(5, 0.05));
  const MeshTopology t = make_topology(g);
  const Points3 gt = gdsr_test::bumpy(g.V, 0.2, 1.0, 1), pred = gdsr_test::bumpy(g.V, 0.3, 1.0, 2);
  const ag::Tensord X = to_tensor<double>(gt);
  auto reference = [&](const ag::Tensord& x) {
    auto measures = [&](const ag::Tensord& y) {
      const UVGradient<double> f = uv_gradient(y, t);
      const ag::Tensord shear = ag::dot_rows(ag::normalize_rows(f.Fu, 1e-6), ag::normalize_rows(f.Fv, 1e-6));
      return ag::concat_cols<double>({ag::norm_rows(f.Fu), ag::norm_rows(f.Fv), shear});
    };
    const ag::Tensord strain = ag::mul_scalar(ag::l1_loss(measures(x), measures(X).detach()), 3.0);
    const ag::Tensord dihedral = ag::l1_loss(dihedral_angles(x, t), dihedral_angles(X, t).detach());
    return ag::add(ag::mul_scalar(strain, 0.01), ag::mul_scalar(dihedral, 0.003));
  };
  LossConfig cfg = only("c_strain");
  cfg.c_dihedral.on = true;
  ag::Tensord x1 = to_tensor<double>(pred), x2 = to_tensor<double>(pred);
  x1.set_requires_grad(true);
  x2.set_requires_grad(true);
  const ag::Tensord ours = coarse_loss(cfg, t, x1, gt).total, ref = reference(x2);
  CHECK(ours.item() == doctest::Approx(ref.item()).epsilon(1e-14));
  ours.backward();
  ref.backward();
  double largest = 0, diff = 0;
  for (size_t i = 0; i < x1.grad().size(); ++i) {
    largest = std::max(largest, std::abs(x2.grad()[i]));
    diff = std::max(diff, std::abs(x1.grad()[i] - x2.grad()[i]));
  }
  REQUIRE(largest > 0);
  CHECK(diff < 1e-13 * largest);
}

TEST_CASE("losses: one degenerate triangle in a fine patch cannot dominate a training step") {
  // The fine loss (reference weights; VGG off: no callback) on three 24-pixel patches of a 1 cm
  // HR grid, with one triangle inside the first patch made degenerate in the prediction.
  // Per-vertex gradient norms at its corners stay within 100 x the healthy prediction's
  // median over the batch (measured: 2 x for a sliver or zero area, 31 x and 44 x for
  // coincident vertices and a point, from the shear term, whose bound scales as 1 / kShearEps).
  const GarmentMesh g = gdsr_test::cut_garment(21, 0.01);
  PatchConfig pc;
  pc.size = 24;
  pc.count = 3;
  const PatchSampler sampler(rasterize_uv(g.UV, g.FUV, 128, 128, 4), g, std::vector<int>(g.V.rows(), 0), pc);
  std::mt19937_64 rng(11);
  const PatchBatch batch = sampler.sample(rng);
  const Points3 gt = gdsr_test::bumpy(g.V, 0.3, 1.0, 1);
  const Points3 base = gdsr_test::bumpy(g.V, 0.25, 1.0, 2);
  // A face of patch 0 with all three corners inside the patch.
  const Patch& p0 = batch.patches[0];
  int face = -1;
  for (int f = 0; f < p0.local_faces.rows() && face < 0; ++f)
    if (p0.local_faces.row(f).maxCoeff() < p0.num_inside) face = f;
  REQUIRE(face >= 0);
  const int a = p0.vertices[p0.local_faces(face, 0)], b = p0.vertices[p0.local_faces(face, 1)],
            c = p0.vertices[p0.local_faces(face, 2)];
  auto row_of = [&](int v) {
    return static_cast<int>(std::lower_bound(batch.vertices.begin(), batch.vertices.end(), v) - batch.vertices.begin());
  };
  auto vertex_gradients = [&](const Points3& pred, const LossConfig& cfg) {
    ag::Tensord x = rows_of(pred, batch.vertices);
    x.set_requires_grad(true);
    fine_loss(cfg, batch, x, gt).total.backward();
    REQUIRE(finite(x.grad()));
    return gdsr_test::vertex_norms(x.grad());
  };
  const double median = gdsr_test::median(vertex_gradients(base, LossConfig{}));
  REQUIRE(median > 0);
  for (const gdsr_test::DegenerateCase& dc : gdsr_test::degenerate_cases(base, a, b, c)) {
    const std::string& name = dc.name;
    const Points3& pred = dc.P;
    INFO(name);
    const std::vector<double> n = vertex_gradients(pred, LossConfig{});
    const double worst = std::max({n[row_of(a)], n[row_of(b)], n[row_of(c)]});
    std::string terms;
    for (const char* term : {"f_position", "f_image_l1", "f_strain", "f_smooth"}) {
      const std::vector<double> m = vertex_gradients(pred, only(term));
      terms +=
          std::string(" ") + term + " " + std::to_string(std::max({m[row_of(a)], m[row_of(b)], m[row_of(c)]}) / median);
    }
    MESSAGE(name << ": " << worst / median << " x the healthy median;" << terms);
    CHECK(worst < 100 * median);
  }
}

// Hyper-net A: a triangle's field parameters do not depend on which other triangles are
// asked for, although A's first linear map runs per vertex (then gathered) when there are
// more triangles than vertices and on the gathered corner rows otherwise.
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "autograd/gradcheck.hpp"
#include "gdsr/model/model_a.hpp"
#include "gdsr/model/model_config.hpp"
#include "tests/support/ag_test_util.hpp"
#include "tests/support/grid_garment.hpp"

#include <algorithm>
#include <cmath>
#include <string>

using namespace gdsr;

namespace {
// A float64 tiny-preset A, an n x n grid and a smooth z_detail on its vertices; `all` lists
// every triangle (more of them than vertices: A's per-vertex path).
struct Setup {
  ModelConfig cfg = load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
  nn::Rng rng;
  HyperNet<double> a;
  GarmentMesh m;
  ag::Tensord z;
  ag::Index all;
  Setup(int n, uint64_t seed, double freq) : rng(seed), a(cfg, rng) {
    m = gdsr_test::grid_garment(gdsr_test::GridSpec::square(n, 0.2));
    z = ag::Tensord::zeros({m.V.rows(), cfg.a_widths.front() / 3});
    for (int64_t i = 0; i < z.numel(); ++i) z.data()[i] = std::sin(freq * static_cast<double>(i) + 0.3);
    all.resize(static_cast<size_t>(m.F.rows()));
    for (size_t f = 0; f < all.size(); ++f) all[f] = static_cast<int64_t>(f);
    REQUIRE(static_cast<int64_t>(all.size()) > m.V.rows());
  }
};
}  // namespace

TEST_CASE("model A: field parameters of a triangle are the same asked alone or with every triangle") {
  const Setup s(5, 5, 0.7);
  const HyperNet<double>& a = s.a;
  const ag::Index& all = s.all;
  const ag::Index few{7, 2, 30};
  REQUIRE(static_cast<int64_t>(few.size()) < s.m.V.rows());  // gathered path
  const FieldParams<double> p_all = a.parameters_for(s.m.F, all, s.z), p_few = a.parameters_for(s.m.F, few, s.z);
  double scale = 0, diff = 0;
  for (size_t i = 0; i < few.size(); ++i)
    for (int64_t j = 0; j < p_all.re.cols(); ++j) {
      scale = std::max({scale, std::abs(p_all.re.at(few[i], j)), std::abs(p_all.im.at(few[i], j))});
      diff = std::max({diff, std::abs(p_all.re.at(few[i], j) - p_few.re.at(static_cast<int64_t>(i), j)),
                       std::abs(p_all.im.at(few[i], j) - p_few.im.at(static_cast<int64_t>(i), j))});
    }
  CHECK(scale > 1e-3);
  CHECK(diff < 1e-12 * scale);  // float64: the two paths differ only in rounding
}

// The whole-model gradient check asks for fewer triangles than vertices; this one checks the
// per-vertex path (every triangle of the grid), with respect to z_detail.
TEST_CASE("model A: float64 gradient check with every triangle asked for") {
  const Setup s(4, 6, 1.3);
  const auto r = ag::gradcheck(
      [&](const std::vector<ag::Tensord>& in) {
        const FieldParams<double> p = s.a.parameters_for(s.m.F, s.all, in[0]);
        return ag::add(p.re, ag::mul_scalar(p.im, 0.5));
      },
      {s.z});
  CHECK(r.checked > 0);
  CHECK_MESSAGE(r.max_rel_error < 1e-6, r.report());  // no leaky ReLU kink lies within a step here
}

TEST_CASE("model A: z_detail of the wrong width names the op") {
  const Setup s(4, 5, 0.7);
  const ag::Tensord z = ag::Tensord::zeros({s.m.V.rows(), 5});
  CHECK_THROWS_WITH(s.a.parameters_for(s.m.F, ag::Index{0}, z), doctest::Contains("model_a"));
}

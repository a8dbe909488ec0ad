// SimParams::substep_travel: a frame takes more substeps when its fastest vertex, relative to
// the cloth's mean velocity, would otherwise move farther than substep_travel in one. Checked
// here against the rule as documented, with the speeds read from the solver's velocities.
#include <doctest/doctest.h>

#include "tests/support/cloth_bodies.hpp"
#include "tests/support/square_cloth.hpp"
#include "gdsr/error.hpp"
#include "gdsr/sim/cloth_solver.hpp"

#include <algorithm>
#include <cmath>

using gdsr::Points3;
using gdsr::Vec3;

namespace {

// m/s: the fastest vertex's speed relative to the mean velocity.
double fastest_relative_speed(const Points3& v) {
  const Eigen::RowVector3d mean = v.colwise().mean();
  return (v.rowwise() - mean).rowwise().norm().maxCoeff();
}

}  // namespace

TEST_CASE("adaptive substeps: a sheet falling freely takes `substeps` every frame, however small substep_travel") {
  // The whole sheet moves alike: nothing in it outruns anything else.
  auto g = gdsr_test::square_cloth(0.4, 0.04, 1.0);
  sim::SimParams p;
  p.substep_travel = 1e-6;
  sim::ClothSolver solver(g, gdsr::Faces(), Points3(), p);
  const double dt = 1.0 / 30;
  for (int t = 0; t < 10; ++t) solver.step(Points3(), Points3(), dt);
  CHECK(solver.num_substeps() == 10 * p.substeps);
  // Yet each substep moves the sheet over 10^3 x substep_travel: the rule is relative to the mean.
  const double fall_per_substep = -solver.velocities().col(1).mean() * dt / p.substeps;
  CAPTURE(fall_per_substep);
  CHECK(fall_per_substep > 1e3 * p.substep_travel);
}

TEST_CASE("adaptive substeps: a sheet flicked by a fast sphere takes enough substeps, in quarters, up to the most") {
  // A sheet draped on a sphere that rises 0.1 m a frame (3 m/s) for 4 frames, then stops: the
  // centre goes with the sphere, the rim is left behind and then flaps.
  const double r = 0.2, dt = 1.0 / 30;
  const auto sphere = sim::make_sphere(Vec3(0, 0, 0), r, 24, 48);
  auto g = gdsr_test::square_cloth(0.6, 0.03, r + 0.02);
  for (int max_substeps : {80, 30}) {
    CAPTURE(max_substeps);
    sim::SimParams p;
    p.substep_travel = 0.002;
    p.max_substeps = max_substeps;
    sim::ClothSolver solver(g, sphere.F, sphere.V, p);
    const int quantum = p.substeps / 4;
    Points3 from = sphere.V;
    int above = 0, capped = 0;
    long long total = 0;
    for (int t = 0; t < 30; ++t) {
      Points3 to = from;
      if (t >= 10 && t < 14) to.col(1).array() += 0.1;
      const int n = solver.substeps_for(dt);
      const double needed = fastest_relative_speed(solver.velocities()) * dt / p.substep_travel;
      CAPTURE(t);
      CAPTURE(needed);
      CHECK(n >= p.substeps);
      CHECK(n <= max_substeps);
      CHECK((n - p.substeps) % quantum == 0);
      if (n < max_substeps) CHECK(n >= needed);         // enough
      if (n > p.substeps) CHECK(n - quantum < needed);  // and no more than a quarter beyond
      if (n == p.substeps) CHECK(needed <= p.substeps);
      above += n > p.substeps;
      capped += n == max_substeps && needed > max_substeps;
      solver.step(from, to, dt);
      total += n;
      REQUIRE(solver.num_substeps() == total);
      from = to;
    }
    CHECK(above >= 3);  // the flick and the flapping that follows it
    if (max_substeps == 30) CHECK(capped >= 1);
    CHECK(solver.positions().allFinite());
  }
}

TEST_CASE("adaptive substeps: a negative or non-finite substep_travel, or fewer most than least substeps, is refused") {
  auto g = gdsr_test::square_cloth(0.2, 0.05, 0.0);
  for (double travel : {-1e-3, std::nan(""), double(INFINITY)}) {
    sim::SimParams p;
    p.substep_travel = travel;
    CHECK_THROWS_WITH(sim::ClothSolver(g, gdsr::Faces(), Points3(), p),
                      doctest::Contains("substep_travel must be finite and >= 0"));
  }
  sim::SimParams p;
  p.substep_travel = 0.003;
  p.max_substeps = p.substeps - 1;
  CHECK_THROWS_WITH(sim::ClothSolver(g, gdsr::Faces(), Points3(), p),
                    doctest::Contains("max_substeps must be >= substeps"));
}

// Cantilever bending test as in a textile lab (ASTM D1388, bending length): a strip clamped
// at one end sticks out horizontally and droops under its own weight. The simulated static
// shape at 30 mm and 10 mm particle distance is compared with the heavy elastica, which this
// test solves itself:  B theta''(s) = -w (L - s) cos theta(s),  theta(0) = 0, theta'(L) = 0
// (theta the downward slope angle, s arc length from the clamp, B the bending rigidity per
// unit width in N m, w = rho g the weight per area in N/m^2), by shooting on theta'(0).
#include <doctest/doctest.h>

#include "gdsr/sim/cloth_solver.hpp"
#include "gdsr/sim/garments.hpp"

#include <cmath>
#include <vector>
#include <functional>

using gdsr::Points3;
using gdsr::Vec3;

namespace {

struct ElasticaTip {
  double x = 0, drop = 0, angle = 0;  // tip position (m from the clamp, m below it), tip slope (rad)
};

// Integrates the elastica from the clamp with theta'(0) = k (RK4, n steps); returns the tip
// and theta'(L) through `end_curvature`.
ElasticaTip integrate(double L, double w_over_B, double k, int n, double* end_curvature) {
  const double ds = L / n;
  double th = 0, om = k, x = 0, y = 0;
  auto f = [&](double s, double t, double o, double& dt, double& dout, double& dx, double& dy) {
    dt = o;
    dout = -w_over_B * (L - s) * std::cos(t);
    dx = std::cos(t);
    dy = std::sin(t);
  };
  for (int i = 0; i < n; ++i) {
    const double s = i * ds;
    double a[4], b[4], c[4], d[4];
    f(s, th, om, a[0], a[1], a[2], a[3]);
    f(s + ds / 2, th + ds / 2 * a[0], om + ds / 2 * a[1], b[0], b[1], b[2], b[3]);
    f(s + ds / 2, th + ds / 2 * b[0], om + ds / 2 * b[1], c[0], c[1], c[2], c[3]);
    f(s + ds, th + ds * c[0], om + ds * c[1], d[0], d[1], d[2], d[3]);
    th += ds / 6 * (a[0] + 2 * b[0] + 2 * c[0] + d[0]);
    om += ds / 6 * (a[1] + 2 * b[1] + 2 * c[1] + d[1]);
    x += ds / 6 * (a[2] + 2 * b[2] + 2 * c[2] + d[2]);
    y += ds / 6 * (a[3] + 2 * b[3] + 2 * c[3] + d[3]);
  }
  *end_curvature = om;
  return {x, y, th};
}

// Heavy elastica of a strip of length L (m), rigidity B (N m), weight w (N/m^2): bisection on
// the clamp curvature so that the free end carries no moment.
ElasticaTip heavy_elastica(double L, double B, double w) {
  double lo = 0, hi = w * L * L / (2 * B);  // linear theory's clamp curvature bounds it above
  for (int it = 0; it < 200; ++it) {
    const double k = 0.5 * (lo + hi);
    double end = 0;
    integrate(L, w / B, k, 2000, &end);
    (end > 0 ? hi : lo) = k;  // too much clamp curvature leaves the tip still curving
  }
  double end = 0;
  return integrate(L, w / B, 0.5 * (lo + hi), 2000, &end);
}

// Strip of free length L and width W (m) plus two clamped columns behind x = 0, meshed as a
// structured grid at particle distance h (alternating diagonals), lying flat at y = 0.
// UV = (x, z). Clamped (pinned) vertices: x <= 0.
sim::Garment strip(double L, double W, double h) {
  const int nx = static_cast<int>(std::lround(L / h)) + 2;  // columns at x = -h .. L
  const int nz = std::max(2, static_cast<int>(std::lround(W / h)) + 1);
  const double dx = L / (nx - 2), dz = W / (nz - 1);
  sim::Garment g;
  g.name = "strip";
  g.particle_distance = h;
  auto& m = g.mesh;
  m.V.resize(nx * nz, 3);
  m.UV.resize(nx * nz, 2);
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nz; ++j) {
      const int v = i * nz + j;
      const double x = (i - 1) * dx, z = j * dz;
      m.V.row(v) << x, 0, z;
      m.UV.row(v) << x, z;
      m.uv_to_vertex.push_back(v);
      if (i <= 1) g.pinned.push_back(v);
    }
  std::vector<Eigen::Vector3i> faces;
  for (int i = 0; i + 1 < nx; ++i)
    for (int j = 0; j + 1 < nz; ++j) {
      const int a = i * nz + j, b = (i + 1) * nz + j, c = (i + 1) * nz + j + 1, d = i * nz + j + 1;
      if ((i + j) % 2 == 0) {
        faces.emplace_back(a, d, c);  // counter-clockwise in (x, z) seen from -y... any orientation works
        faces.emplace_back(a, c, b);
      } else {
        faces.emplace_back(a, d, b);
        faces.emplace_back(b, d, c);
      }
    }
  m.F.resize(faces.size(), 3);
  for (size_t f = 0; f < faces.size(); ++f) m.F.row(f) = faces[f].transpose();
  m.FUV = m.F;
  return g;
}

// Static droop of the strip (mean over the tip row): returns tip x and drop below the clamp.
ElasticaTip simulate_strip(double L, double W, double h, double rho, double B, bool implicit_bending = true) {
  const auto g = strip(L, W, h);
  sim::SimParams p;
  p.density = rho;
  p.bend_stiffness = B;
  p.damping = 4;  // settle quickly; the static shape does not depend on it
  p.implicit_bending = implicit_bending;
  // The Gauss-Seidel bending passes leave the 10 mm strip chattering (2 cm/s) against the soft
  // compression; that path is only the comparison below, so it runs with compression as stiff
  // as stretch.
  if (!implicit_bending) p.compression_ratio = 1;
  p.settle_frames = 0;
  sim::ClothSolver solver(g, gdsr::Faces(), Points3(), p);
  for (int t = 0; t < 120; ++t) solver.step(Points3(), Points3(), 1.0 / 30);  // 4 s
  const auto& X = solver.positions();
  ElasticaTip tip;
  int n = 0;
  const double xmax = g.mesh.V.col(0).maxCoeff();
  for (int v = 0; v < X.rows(); ++v)
    if (g.mesh.V(v, 0) > xmax - 1e-9) {
      tip.x += X(v, 0);
      tip.drop += -X(v, 1);
      ++n;
    }
  tip.x /= n;
  tip.drop /= n;
  const double sp = solver.velocities().rowwise().norm().maxCoeff();
  CAPTURE(sp);
  CHECK(sp < 0.01);  // at rest (m/s)
  return tip;
}

}  // namespace

TEST_CASE("cantilever: the elastica solver reproduces ASTM D1388's 41.5 degree relation") {
  // D1388: the overhang at which the tip chord falls 41.5 degrees below horizontal is twice
  // the bending length c = (B / w)^(1/3) (Peirce's approximation of the heavy elastica).
  const double B = 1e-3, w = 1.0, c = std::cbrt(B / w);
  const auto tip = heavy_elastica(2 * c, B, w);
  const double chord = std::atan2(tip.drop, tip.x) * 180 / M_PI;
  CAPTURE(chord);
  CHECK(chord == doctest::Approx(41.5).epsilon(0.03));
  // Small load: linear beam theory, tip drop w L^4 / (8 B).
  const auto lin = heavy_elastica(0.1, 1.0, 1.0);
  CHECK(lin.drop == doctest::Approx(1e-4 / 8).epsilon(1e-3));
}

// The same fabric at both resolutions. With Gauss-Seidel bending passes the 10 mm strip hung
// almost vertically (tip x 0.03 m against 0.17 m at 30 mm); with the implicit bending solve
// the two agree within 6%. Both still droop more than the elastica, by the same amount with
// 3x the passes or 3x the substeps (measured: converged), so the remaining difference is the
// discrete bending model on this strip, not the solver: the tolerance against the elastica
// is 20% (HR is 11-12% off, LR 15-17%), the one between resolutions 6%.
TEST_CASE("cantilever: a strip droops like the heavy elastica at 30 mm and at 10 mm") {
  // A 0.3 m overhang, 0.09 m wide, of a 200 g/m^2 fabric whose bending length is 0.15 m
  // (L = 2c: the D1388 test point, tip chord near 41.5 degrees).
  const double L = 0.3, W = 0.09, rho = 0.2, g = 9.81, c = 0.15;
  const double w = rho * g, B = w * c * c * c;
  const auto ref = heavy_elastica(L, B, w);
  std::vector<ElasticaTip> tips;
  for (double h : {0.03, 0.01}) {
    const auto sim = simulate_strip(L, W, h, rho, B);
    CAPTURE(h);
    MESSAGE("cantilever h=" << h << ": tip drop " << sim.drop << " m (elastica " << ref.drop << "), tip x " << sim.x
                            << " m (elastica " << ref.x << ")");
    CHECK(sim.drop == doctest::Approx(ref.drop).epsilon(0.20));
    CHECK(sim.x == doctest::Approx(ref.x).epsilon(0.20));
    tips.push_back(sim);
  }
  CHECK(tips[1].drop == doctest::Approx(tips[0].drop).epsilon(0.06));
  CHECK(tips[1].x == doctest::Approx(tips[0].x).epsilon(0.06));
}

TEST_CASE("cantilever: Gauss-Seidel bending passes leave the 10 mm strip far softer than the 30 mm one") {
  // Why the implicit solve is the default: the same fabric, the passes alone.
  const double L = 0.3, W = 0.09, rho = 0.2, c = 0.15, B = rho * 9.81 * c * c * c;
  const auto lr = simulate_strip(L, W, 0.03, rho, B, false), hr = simulate_strip(L, W, 0.01, rho, B, false);
  MESSAGE("Gauss-Seidel bending: tip x " << lr.x << " m at 30 mm, " << hr.x << " m at 10 mm");
  CHECK(hr.x < 0.5 * lr.x);
}

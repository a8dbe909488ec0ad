#include <doctest/doctest.h>

#include "gdsr/body/body_query.hpp"
#include "infer/collision.hpp"
#include "tests/support/loss_test_meshes.hpp"

#include <cmath>

using namespace gdsr;

namespace {

// Body = the plane y = 0 with outward normal +y; counts its calls.
struct PlaneBody {
  int calls = 0;
  BodyQueryFn fn() {
    return [this](const Points3& q, Points3& closest, Points3& normal) {
      ++calls;
      closest = q;
      closest.col(1).setZero();
      normal.resize(q.rows(), 3);
      normal.rowwise() = Eigen::RowVector3d(0, 1, 0);
    };
  }
};

}  // namespace

TEST_CASE("collision: body pass pushes penetrating HR vertices to sigma_b and leaves far ones") {
  Points3 C(2, 3);
  C << 0, 0.005, 0,  // within sigma_b of the body: collides
      1, 0.5, 0;     // far away
  Points3 G(4, 3);
  G << 0.01, -0.01, 0,  // penetrating, nearest LR 0 -> pushed to y = sigma_b
      -0.01, 0.05, 0,   // nearest LR 0 but already outside sigma_b -> untouched
      1.01, -0.2, 0,    // penetrating but its LR vertex 1 does not collide -> untouched
      0.99, 0.4, 0;     // far
  const Points3 G0 = G;
  const std::vector<int> nearest = {0, 0, 1, 1};
  PlaneBody body;
  const BodyQueryFn q = body.fn();
  CollisionInput in;
  in.C_hat = &C;
  in.hr_nearest_lr = &nearest;
  in.body = &q;
  CollisionConfig cfg;
  const CollisionStats st = resolve_collisions(cfg, in, G);
  CHECK(body.calls == 2);  // the LR vertices, then the HR vertices of the colliding one
  CHECK(st.body_queried);
  CHECK(st.lr_body == 1);
  CHECK(st.hr_queried == 2);
  CHECK(st.hr_body == 1);
  CHECK(G(0, 1) == doctest::Approx(cfg.sigma_b));
  CHECK(G(0, 0) == G0(0, 0));  // moved along the normal only
  CHECK(G(0, 2) == G0(0, 2));
  for (int r = 1; r < 4; ++r) CHECK(G.row(r) == G0.row(r));
  CHECK(!st.layers_checked);  // single layer: no layer work
}

TEST_CASE("collision: no body means no query / switching the body pass off too") {
  Points3 C(1, 3);
  C << 0, -0.1, 0;
  Points3 G(1, 3);
  G << 0, -0.1, 0;
  const std::vector<int> nearest = {0};
  CollisionInput in;
  in.C_hat = &C;
  in.hr_nearest_lr = &nearest;
  CollisionStats st = resolve_collisions({}, in, G);
  CHECK(!st.body_queried);
  CHECK(st.hr_body == 0);
  PlaneBody body;
  const BodyQueryFn q = body.fn();
  in.body = &q;
  CollisionConfig off;
  off.body = false;
  st = resolve_collisions(off, in, G);
  CHECK(body.calls == 0);
  CHECK(G(0, 1) == -0.1);
  st = resolve_collisions({}, in, G);
  CHECK(body.calls == 2);  // the LR vertex, then its HR vertex
  CHECK(G(0, 1) == doctest::Approx(0.015));
}

TEST_CASE("collision: a two-layer garment pushes the exterior layer out of the interior one") {
  // Interior layer: flat grid at z = 0 (normal +z); exterior: the same grid lifted to z = 0.01
  // (closer than sigma_l = 0.02), plus one exterior vertex far beyond the interior's edge.
  const GarmentMesh in0 = gdsr_test::grid_garment(gdsr_test::GridSpec::spaced(4, 0.03));
  const int n0 = static_cast<int>(in0.V.rows());
  Points3 C(2 * n0 + 1, 3);
  Faces F(2 * in0.F.rows(), 3);
  C.topRows(n0) = in0.V;
  C.middleRows(n0, n0) = in0.V;
  C.middleRows(n0, n0).col(2).setConstant(0.01);
  C.row(2 * n0) << 0.5, 0.5, 0.005;  // exterior layer but 0.4 m from any interior vertex (> gamma)
  F.topRows(in0.F.rows()) = in0.F;
  F.bottomRows(in0.F.rows()) = in0.F.array() + n0;
  std::vector<int> layer(2 * n0 + 1, 1);
  for (int i = 0; i < n0; ++i) layer[i] = 0;

  // HR: one vertex per LR vertex, slightly below it.
  Points3 G = C;
  G.col(2).array() -= 0.004;
  const Points3 G0 = G;
  std::vector<int> nearest(G.rows());
  for (int i = 0; i < G.rows(); ++i) nearest[i] = i;
  CollisionInput in;
  in.C_hat = &C;
  in.lr_F = &F;
  in.lr_layer = &layer;
  in.hr_nearest_lr = &nearest;
  CollisionConfig cfg;
  const CollisionStats st = resolve_collisions(cfg, in, G);
  CHECK(st.layers_checked);
  CHECK(!st.body_queried);
  CHECK(st.lr_layer == n0);
  CHECK(st.hr_layer == n0);
  for (int i = 0; i < n0; ++i) {
    CHECK(G.row(i) == G0.row(i));                         // interior layer untouched
    CHECK(G(n0 + i, 2) == doctest::Approx(cfg.sigma_l));  // exterior pushed to sigma_l along +z
    CHECK(G(n0 + i, 0) == G0(n0 + i, 0));
  }
  CHECK(G.row(2 * n0) == G0.row(2 * n0));  // beyond gamma: not a collision

  // Layers switched off, or a single-layer garment: nothing moves.
  Points3 H = G0;
  CollisionConfig off;
  off.layers = false;
  CHECK(resolve_collisions(off, in, H).hr_layer == 0);
  CHECK(H == G0);
  std::vector<int> one(layer.size(), 0);
  in.lr_layer = &one;
  const CollisionStats s1 = resolve_collisions(cfg, in, H);
  CHECK(!s1.layers_checked);
  CHECK(H == G0);
}

TEST_CASE("collision: inconsistent inputs throw") {
  Points3 C(2, 3);
  C.setZero();
  Points3 G(3, 3);
  G.setZero();
  std::vector<int> nearest = {0, 1};
  CollisionInput in;
  in.C_hat = &C;
  in.hr_nearest_lr = &nearest;
  CHECK_THROWS(resolve_collisions({}, in, G));
  nearest = {0, 1, 5};
  CHECK_THROWS(resolve_collisions({}, in, G));
}

TEST_CASE("collision: the Embree body adapter pushes out of a real body mesh") {
  // A closed box body [-0.5, 0.5]^3 (12 outward triangles); the LR vertex sits 5 mm outside
  // the top face, its HR vertex 10 mm inside.
  TriMesh box;
  box.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) box.V.row(i) << (i & 1 ? 0.5 : -0.5), (i & 2 ? 0.5 : -0.5), (i & 4 ? 0.5 : -0.5);
  box.F.resize(12, 3);
  box.F << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5;
  const BodyQuery q(box);
  const BodyQueryFn fn = body_query_fn(q);
  Points3 C(1, 3);
  C << 0.1, 0.505, -0.05;
  Points3 G(1, 3);
  G << 0.12, 0.49, -0.04;
  const std::vector<int> nearest = {0};
  CollisionInput in;
  in.C_hat = &C;
  in.hr_nearest_lr = &nearest;
  in.body = &fn;
  const CollisionStats st = resolve_collisions({}, in, G);
  CHECK(st.lr_body == 1);
  CHECK(st.hr_body == 1);
  // Moved along its own (smooth) body normal to offset sigma_b from its body point.
  Points3 G0(1, 3);
  G0 << 0.12, 0.49, -0.04;
  const ClosestPoints c = q.closest(G0);
  const Vec3 n = c.normal.row(0).transpose(), b = c.point.row(0).transpose();
  const Vec3 g = G.row(0).transpose(), g0(0.12, 0.49, -0.04);
  CHECK((g - b).dot(n) == doctest::Approx(0.015));
  CHECK((g - g0).cross(n).norm() < 1e-12);
  CHECK(n.y() > 0.5);
}

TEST_CASE("collision: on a curved body each HR vertex leaves its own tangent plane, the paper's rule its LR vertex's") {
  // Body: the sphere of radius R about the origin (closest point and normal in closed form).
  // The LR vertex sits on top, 2 mm out: it collides. HR vertex 0 lies 1 mm beyond sigma_b off
  // the sphere at 0.3 rad from the top (outside: stays); HR vertex 1 at the same angle 5 mm off
  // (pushed radially to sigma_b). Both lie behind the LR vertex's plane y = R + sigma_b.
  const double R = 0.1, sigma = 0.015, a = 0.3;
  const BodyQueryFn sphere = [R](const Points3& q, Points3& closest, Points3& normal) {
    normal = q.rowwise().normalized();
    closest = R * normal;
  };
  Points3 C(1, 3);
  C << 0, R + 0.002, 0;
  Points3 G(2, 3);
  G << (R + sigma + 0.001) * std::sin(a), (R + sigma + 0.001) * std::cos(a), 0,  //
      (R + 0.005) * std::sin(a), (R + 0.005) * std::cos(a), 0;
  const Points3 G0 = G;
  const std::vector<int> nearest = {0, 0};
  CollisionInput in;
  in.C_hat = &C;
  in.hr_nearest_lr = &nearest;
  in.body = &sphere;
  CollisionConfig cfg;
  cfg.sigma_b = sigma;
  CollisionStats st = resolve_collisions(cfg, in, G);
  CHECK(st.hr_body == 1);
  CHECK(G.row(0) == G0.row(0));
  CHECK(G.row(1).norm() == doctest::Approx(R + sigma).epsilon(1e-12));
  CHECK(G(1, 0) / G(1, 1) == doctest::Approx(std::tan(a)).epsilon(1e-12));  // radially
  // The paper's rule: both move up to the LR vertex's plane, y = R + sigma.
  G = G0;
  cfg.hr_planes = false;
  st = resolve_collisions(cfg, in, G);
  CHECK(st.hr_body == 2);
  CHECK(st.hr_queried == 0);
  CHECK(G(0, 1) == doctest::Approx(R + sigma).epsilon(1e-12));
  CHECK(G(0, 1) - G0(0, 1) > 0.004);  // (R + sigma) - (R + sigma + 1 mm) cos a = 4.2 mm
  CHECK(G(1, 1) == doctest::Approx(R + sigma).epsilon(1e-12));
  CHECK(G(0, 0) == G0(0, 0));
}

TEST_CASE("collision: on a curved inner layer each HR vertex leaves its own tangent plane, and none beside its edge") {
  // Inner layer (0): an open cylinder of radius R about the z axis, 64 segments, z in [0, 0.1],
  // normals outwards. Exterior LR vertex e (layer 1) 2 mm outside it at angle 0: it collides.
  // Its HR vertices, at segment 4's angle a (a mesh vertex, whose smooth normal is radial):
  // 0 lies 1 mm beyond sigma_l (stays), 1 lies 2 mm out (pushed radially to sigma_l); 2 lies
  // 3 cm below the layer's open edge (beside it, not over it: stays). The paper's rule pushes
  // all three to the LR vertex's plane x = R + sigma_l.
  const double R = 0.1, sigma = 0.02, a = 4 * 2 * M_PI / 64;
  const int seg = 64, rings = 5;
  const int ni = seg * rings, e = ni;
  Points3 C(ni + 1, 3);
  for (int j = 0; j < rings; ++j)
    for (int s = 0; s < seg; ++s)
      C.row(j * seg + s) << R * std::cos(2 * M_PI * s / seg), R * std::sin(2 * M_PI * s / seg), 0.025 * j;
  C.row(e) << R + 0.002, 0, 0.05;
  Faces F(2 * seg * (rings - 1), 3);
  for (int j = 0, f = 0; j + 1 < rings; ++j)
    for (int s = 0; s < seg; ++s) {
      const int v00 = j * seg + s, v01 = j * seg + (s + 1) % seg, v11 = v01 + seg, v10 = v00 + seg;
      F.row(f++) << v00, v01, v11;
      F.row(f++) << v00, v11, v10;
    }
  std::vector<int> layer(ni + 1, 0);
  layer[e] = 1;
  Points3 G(3, 3);
  G << (R + sigma + 0.001) * std::cos(a), (R + sigma + 0.001) * std::sin(a), 0.05,  //
      (R + 0.002) * std::cos(a), (R + 0.002) * std::sin(a), 0.05,                   //
      R, 0, -0.03;
  const Points3 G0 = G;
  const std::vector<int> nearest = {e, e, e};
  CollisionInput in;
  in.C_hat = &C;
  in.lr_F = &F;
  in.lr_layer = &layer;
  in.hr_nearest_lr = &nearest;
  CollisionConfig cfg;
  cfg.sigma_l = sigma;
  CollisionStats st = resolve_collisions(cfg, in, G);
  CHECK(st.lr_layer == 1);
  CHECK(st.hr_layer_queried == 3);
  CHECK(st.hr_layer == 1);
  CHECK(G.row(0) == G0.row(0));
  CHECK(G.row(1).head<2>().norm() == doctest::Approx(R + sigma).epsilon(1e-12));
  CHECK(G(1, 1) / G(1, 0) == doctest::Approx(std::tan(a)).epsilon(1e-12));  // radially
  CHECK(G(1, 2) == doctest::Approx(0.05).epsilon(1e-12));
  CHECK(G.row(2) == G0.row(2));
  // The paper's rule: every HR vertex of e up to the plane of e's nearest inner vertex.
  G = G0;
  cfg.hr_planes = false;
  st = resolve_collisions(cfg, in, G);
  CHECK(st.hr_layer == 3);
  CHECK(st.hr_layer_queried == 0);
  for (int k = 0; k < 3; ++k) CHECK(G(k, 0) == doctest::Approx(R + sigma).epsilon(1e-12));
  CHECK(G(0, 0) - G0(0, 0) > 0.008);  // (R + sigma) - (R + sigma + 1 mm) cos a = 8.2 mm
}

TEST_CASE("collision: the body offset is the flag, else the dataset's simulation thickness, else the paper's") {
  nlohmann::json sim = {{"thickness_m", 0.004}};
  CHECK(gdsr::body_offset_for(sim, -1) == 0.004);
  CHECK(gdsr::body_offset_for(sim, 0.01) == 0.01);
  CHECK(gdsr::body_offset_for(sim, 0) == 0.0);  // 0 given: no offset, the plain surface
  CHECK(gdsr::body_offset_for(nlohmann::json::object(), -1) == 0.015);  // imported data: the paper's
  CHECK(gdsr::body_offset_for({{"thickness_m", "4 mm"}}, -1) == 0.015);  // not a number: ignored
  CHECK(gdsr::body_offset_for({{"thickness_m", 2.0}}, -1) == 0.015);     // 2 m is not a thickness
}

TEST_CASE("collision: the layer offset is the flag, else the dataset's layer gap, else the paper's") {
  const nlohmann::json sim = {{"thickness_m", 0.004}, {"layer_gap_m", 0.003}};
  CHECK(gdsr::layer_offset_for(sim, -1) == 0.003);
  CHECK(gdsr::layer_offset_for(sim, 0.01) == 0.01);
  CHECK(gdsr::layer_offset_for(sim, 0) == 0.0);
  // Our solver's data from before the layer gap was recorded: its thickness, the same 4 mm.
  CHECK(gdsr::layer_offset_for({{"thickness_m", 0.004}}, -1) == 0.004);
  CHECK(gdsr::layer_offset_for(nlohmann::json::object(), -1) == 0.020);  // imported data: the paper's
  CHECK(gdsr::layer_offset_for({{"layer_gap_m", "4 mm"}, {"thickness_m", 0.005}}, -1) == 0.005);  // not a number
  CHECK(gdsr::layer_offset_for({{"layer_gap_m", 2.0}}, -1) == 0.020);                             // 2 m is not a gap
}

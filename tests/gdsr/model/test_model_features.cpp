// Graph features (23 node values, 9 edge values), the static graph and layer edges,
// checked against values computed by hand on a two-triangle mesh.
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/model/features.hpp"
#include "gdsr/model/graph.hpp"
#include "gdsr/model/model_config.hpp"
#include "tests/support/body_contact.hpp"
#include "tests/support/model_test_util.hpp"

#include <cmath>

using namespace gdsr;

namespace {

// Square of side s in the x-z plane at height 0.01 m: v0 (0,0), v1 (s,0), v2 (s,s), v3 (0,s)
// in (x, z); faces (0,3,1) and (1,3,2), both with normal +y when flat.
GarmentMesh two_triangles(double s) {
  GarmentMesh g;
  g.V.resize(4, 3);
  g.V << 0, 0.01, 0, s, 0.01, 0, s, 0.01, s, 0, 0.01, s;
  g.F.resize(2, 3);
  g.F << 0, 3, 1, 1, 3, 2;
  g.UV = g.V(Eigen::all, std::vector<int>{0, 2});
  g.FUV = g.F;
  g.uv_to_vertex = {0, 1, 2, 3};
  return g;
}

}  // namespace

TEST_CASE("model features: two-triangle mesh against hand-computed values") {
  const double s = 0.1, lift = 0.05;
  const GarmentMesh mesh = two_triangles(s);
  const GarmentGraph g = build_graph(mesh);
  ModelConfig cfg;

  // Ring-1: edges (0,1), (0,3), (1,2), (1,3), (2,3), both directions; ring-2: only 0 <-> 2.
  REQUIRE(g.ring1_size() == 10);
  REQUIRE(g.ring2_size() == 2);
  CHECK(((g.ring2_src[0] == 0 && g.ring2_dst[0] == 2) || (g.ring2_src[0] == 2 && g.ring2_dst[0] == 0)));
  CHECK(g.num_layers == 1);

  FrameInput in;
  in.C_t = mesh.V;
  in.C_t(2, 1) += lift;  // v2 lifted: face 1 tilts
  in.C_tm1 = in.C_t;
  in.C_tm1.col(0).array() -= 0.01;  // moved +0.01 in x over the last frame
  in.C_tm2 = in.C_tm1;
  in.C_tm2.col(0).array() -= 0.006;  // velocity went 0.006 -> 0.01: acceleration 0.004
  in.Chat_tm1 = in.C_tm1;
  in.Chat_tm1.col(1).array() += 0.002;
  in.Chat_tm2 = in.C_tm2;
  in.Chat_tm2.col(2).array() += 0.003;
  const TriMesh body = gdsr_test::plane_body(0.0);
  in.has_body = true;
  in.contact_t = gdsr_test::closest_points_bruteforce(body, in.C_t);
  in.contact_tm1 = gdsr_test::closest_points_bruteforce(body, in.C_tm1);
  // Closest points on the plane y = 0 are the vertical projections, normal +y.
  for (int i = 0; i < 4; ++i) {
    CHECK(in.contact_t.point(i, 0) == doctest::Approx(in.C_t(i, 0)));
    CHECK(in.contact_t.point(i, 1) == doctest::Approx(0.0));
    CHECK(in.contact_t.normal(i, 1) == doctest::Approx(1.0));
  }

  const auto f = compute_features<double>(g, ag::Tensor<double>::from_eigen(in.C_t), in, cfg);
  REQUIRE(f.node.rows() == 4);
  REQUIRE(f.node.cols() == 23);
  const auto n = f.node.mat();

  // Normals: face 0 cross = (0, s^2, 0); face 1 cross = (v3-v1) x (v2-v1)
  // = (-s, 0, s) x (0, L, s) = (-s L, s^2, -s L) with L = lift.
  const Eigen::Vector3d c0(0, s * s, 0), c1(-s * lift, s * s, -s * lift);
  const Eigen::Vector3d n0 = c0.normalized(), n2 = c1.normalized(), n13 = (c0 + c1).normalized();
  for (int k = 0; k < 3; ++k) {
    CHECK(n(0, k) == doctest::Approx(n0[k]).epsilon(1e-12));
    CHECK(n(2, k) == doctest::Approx(n2[k]).epsilon(1e-12));
    CHECK(n(1, k) == doctest::Approx(n13[k]).epsilon(1e-12));
    CHECK(n(3, k) == doctest::Approx(n13[k]).epsilon(1e-12));
  }
  for (int i = 0; i < 4; ++i) {
    // velocity, acceleration
    CHECK(n(i, 3) == doctest::Approx(0.01));
    CHECK(n(i, 4) == doctest::Approx(0.0));
    CHECK(n(i, 6) == doctest::Approx(0.004));
    CHECK(n(i, 7) == doctest::Approx(0.0));
    // body at t: height 0.01 (v2: 0.06) above the plane; m = max(0.015 - h, 0), p = m n_b.
    const double m = std::max(0.015 - in.C_t(i, 1), 0.0);
    CHECK(n(i, 9) == doctest::Approx(m));
    CHECK(n(i, 10) == doctest::Approx(0.0));
    CHECK(n(i, 11) == doctest::Approx(m));
    CHECK(n(i, 12) == doctest::Approx(0.0));
    // c_{t-1} against the body at t: same heights.
    CHECK(n(i, 13) == doctest::Approx(m));
    CHECK(n(i, 15) == doctest::Approx(m));
    // d_{t-1} = Chat_tm1 - C_tm1 = (0, 0.002, 0); vhat = Chat_tm1 - Chat_tm2.
    CHECK(n(i, 17) == doctest::Approx(0.0));
    CHECK(n(i, 18) == doctest::Approx(0.002));
    CHECK(n(i, 20) == doctest::Approx(0.006));
    CHECK(n(i, 21) == doctest::Approx(0.002));
    CHECK(n(i, 22) == doctest::Approx(-0.003));
  }
  CHECK(n(0, 9) == doctest::Approx(0.005));
  CHECK(n(2, 9) == doctest::Approx(0.0));

  // Edge features: per directed edge src -> dst.
  REQUIRE(f.ring1.cols() == 9);
  const auto e = f.ring1.mat();
  for (int k = 0; k < g.ring1_size(); ++k) {
    const int i = static_cast<int>(g.ring1_src[k]), j = static_cast<int>(g.ring1_dst[k]);
    const Eigen::Vector3d dt = (in.C_t.row(j) - in.C_t.row(i)).transpose();
    const Eigen::Vector3d d1 = (in.C_tm1.row(j) - in.C_tm1.row(i)).transpose();
    for (int c = 0; c < 3; ++c) {
      CHECK(e(k, c) == doctest::Approx(dt[c]));
      CHECK(e(k, 4 + c) == doctest::Approx(d1[c]));
    }
    CHECK(e(k, 3) == doctest::Approx(dt.norm()));
    CHECK(e(k, 7) == doctest::Approx(d1.norm()));
    const bool diagonal = (i == 1 && j == 3) || (i == 3 && j == 1);
    CHECK(e(k, 8) == doctest::Approx(diagonal ? s * std::sqrt(2.0) : s));
  }
  // Single layer: no layer edges, no layer feature tensor.
  CHECK(f.layer_edges.size() == 0);
  CHECK(!f.layer.defined());

  // Without a body the interaction columns are zero; noise changes only the history.
  in.has_body = false;
  nn::Rng noise(7);
  const auto f2 = compute_features<double>(g, ag::Tensor<double>::from_eigen(in.C_t), in, cfg, &noise);
  const auto n2m = f2.node.mat();
  for (int i = 0; i < 4; ++i) {
    for (int c = 9; c < 17; ++c) CHECK(n2m(i, c) == 0.0);
    for (int c = 0; c < 9; ++c) CHECK(n2m(i, c) == n(i, c));
    double diff = 0;
    for (int c = 17; c < 23; ++c) diff += std::abs(n2m(i, c) - n(i, c));
    CHECK(diff > 0);
    CHECK(diff < 6 * 5 * cfg.noise_std);
  }

  // node_length_unit 0.01 (centimetres): the 20 length columns are 100 times larger, the
  // normals unchanged, the edges untouched.
  ModelConfig cm = cfg;
  cm.node_length_unit = 0.01;
  in.has_body = true;
  const auto f3 = compute_features<double>(g, ag::Tensor<double>::from_eigen(in.C_t), in, cm);
  const auto n3 = f3.node.mat();
  for (int i = 0; i < 4; ++i) {
    for (int c = 0; c < 3; ++c) CHECK(n3(i, c) == n(i, c));
    for (int c = 3; c < 23; ++c) CHECK(n3(i, c) == doctest::Approx(100 * n(i, c)).epsilon(1e-12));
  }
  CHECK(n3(0, 18) == doctest::Approx(0.2));  // d_{t-1} = 2 mm = 0.2 cm
  CHECK((f3.ring1.mat() - e).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("model features: layer edges only for multi-layer garments") {
  const double size = 0.1, gap = 0.01;
  ModelConfig cfg;  // sigma_l = 0.02
  const GarmentMesh two = gdsr_test::two_layer_garment(3, size, gap);
  const GarmentGraph g2 = build_graph(two);
  CHECK(g2.num_layers == 2);
  // Vertex v of layer 0 sits 0.01 below vertex v + 9 of layer 1; grid spacing 0.05 > 0.02,
  // so exactly these 9 pairs, both directions.
  const LayerEdges le = find_layer_edges(g2, two.V, cfg.sigma_l);
  REQUIRE(le.size() == 18);
  for (int64_t k = 0; k < le.size(); ++k) CHECK(std::abs(le.src[k] - le.dst[k]) == 9);

  nn::Rng rng(3);
  FrameInput in = gdsr_test::make_frame(two.V, rng, 0.001);
  const auto f = compute_features<double>(g2, ag::Tensor<double>::from_eigen(in.C_t), in, cfg);
  REQUIRE(f.layer_edges.size() == 18);
  REQUIRE(f.layer.defined());
  CHECK(f.layer.rows() == 18);
  for (int64_t k = 0; k < 18; ++k) {
    CHECK(f.layer.at(k, 8) == doctest::Approx(cfg.sigma_l));
    const int i = static_cast<int>(f.layer_edges.src[k]), j = static_cast<int>(f.layer_edges.dst[k]);
    CHECK(f.layer.at(k, 3) == doctest::Approx((in.C_t.row(j) - in.C_t.row(i)).norm()));
  }
  // Pulled apart beyond sigma_l: none.
  Points3 apart = two.V;
  apart.bottomRows(9).col(1).array() += 0.05;
  CHECK(find_layer_edges(g2, apart, cfg.sigma_l).size() == 0);

  // One layer: none, whatever the distances.
  const GarmentMesh one = gdsr_test::grid_garment(gdsr_test::GridSpec::square(3, size));
  const GarmentGraph g1 = build_graph(one);
  CHECK(g1.num_layers == 1);
  CHECK(find_layer_edges(g1, one.V, 1.0).size() == 0);
}

#include "gdsr/geometry/mesh_ops.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <Eigen/LU>

#include <cmath>
#include <queue>
#include <random>
#include <array>
#include <set>

using namespace gdsr;

namespace {

// Graph distances from every vertex (BFS), for the brute-force ring-2 check.
std::vector<std::vector<int>> all_distances(const Faces& F, int n) {
  const Csr nb = vertex_neighbours(F, n);
  std::vector<std::vector<int>> d(n, std::vector<int>(n, -1));
  for (int s = 0; s < n; ++s) {
    std::queue<int> q;
    q.push(s);
    d[s][s] = 0;
    while (!q.empty()) {
      int v = q.front();
      q.pop();
      for (int a = nb.offsets[v]; a < nb.offsets[v + 1]; ++a)
        if (d[s][nb.items[a]] < 0) {
          d[s][nb.items[a]] = d[s][v] + 1;
          q.push(nb.items[a]);
        }
    }
  }
  return d;
}

}  // namespace

TEST_CASE("mesh_ops: normals of a flat grid and area weighting") {
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(4, 3, 1.0, 0.75));
  const Points3 fn = face_normals(g.V, g.F);
  const Points3 vn = vertex_normals(g.V, g.F);
  for (int f = 0; f < fn.rows(); ++f) CHECK((fn.row(f) - Eigen::RowVector3d(0, 0, 1)).norm() < 1e-12);
  for (int v = 0; v < vn.rows(); ++v) CHECK((vn.row(v) - Eigen::RowVector3d(0, 0, 1)).norm() < 1e-12);

  // Vertex 0 shared by a big triangle in z=0 (normal +z) and a small one in x=0 (normal +x).
  Points3 V(5, 3);
  V << 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 1, 0, 1, 0;
  Faces F(2, 3);
  F << 0, 1, 2, 0, 4, 3;
  const Points3 n = vertex_normals(V, F);
  const Eigen::RowVector3d expect = Eigen::RowVector3d(0.5, 0, 2).normalized();  // areas 2 and 0.5
  CHECK((n.row(0) - expect).norm() < 1e-12);
  // Degenerate face: zero normal, no NaN.
  Faces D(1, 3);
  D << 0, 1, 1;
  CHECK(face_normals(V, D).row(0).norm() == 0.0);
}

TEST_CASE("mesh_ops: edges, boundary, face pairs and Euler characteristic of a grid") {
  const int nx = 5, ny = 4;
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(nx, ny, 1.0, 0.8));
  const Pairs E = unique_edges(g.F);
  const int V = static_cast<int>(g.V.rows()), F = static_cast<int>(g.F.rows());
  CHECK(V - E.rows() + F == 1);  // a disk
  for (int e = 0; e < E.rows(); ++e) CHECK(E(e, 0) < E(e, 1));
  const std::vector<int> b = boundary_vertices(g.F);
  CHECK(static_cast<int>(b.size()) == 2 * (nx + ny));
  const FacePairs p = adjacent_face_pairs(g.F);
  CHECK(p.size() == E.rows() - 2 * (nx + ny));  // interior edges
  for (int i = 0; i < p.size(); ++i) {
    for (int s = 0; s < 2; ++s) {
      const int f = p.faces(i, s), o = p.opposite(i, s);
      std::set<int> corners{g.F(f, 0), g.F(f, 1), g.F(f, 2)};
      CHECK(corners.count(p.edge(i, 0)) == 1);
      CHECK(corners.count(p.edge(i, 1)) == 1);
      CHECK(corners.count(o) == 1);
      CHECK(o != p.edge(i, 0));
      CHECK(o != p.edge(i, 1));
    }
  }
  // Unit squares with diagonals: mean edge length is known.
  const GarmentMesh u = gdsr_test::grid_garment(gdsr_test::GridSpec(3, 2, 3.0, 2.0));
  const int axis = 3 * 3 + 4 * 2, diag = 3 * 2;
  CHECK(mean_edge_length(u.V, u.F) == doctest::Approx((axis + diag * std::sqrt(2.0)) / (axis + diag)).epsilon(1e-12));
}

TEST_CASE("mesh_ops: ring-2 pairs match breadth-first distances") {
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(5, 4, 1.0, 1.0).tube());
  const int n = static_cast<int>(g.V.rows());
  const auto d = all_distances(g.F, n);
  std::set<std::pair<int, int>> expect;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (d[i][j] == 2) expect.insert({i, j});
  const Pairs r2 = ring2_pairs(g.F, n);
  std::set<std::pair<int, int>> got;
  for (int k = 0; k < r2.rows(); ++k) got.insert({r2(k, 0), r2(k, 1)});
  CHECK(static_cast<size_t>(r2.rows()) == got.size());  // no duplicates
  CHECK(got == expect);
}

TEST_CASE("mesh_ops: vertex-face adjacency lists every incidence once") {
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(4, 4, 1.0, 1.0).tube());
  const Csr vf = vertex_faces(g.F, static_cast<int>(g.V.rows()));
  CHECK(vf.items.size() == static_cast<size_t>(3 * g.F.rows()));
  for (int v = 0; v < g.V.rows(); ++v)
    for (int a = vf.offsets[v]; a < vf.offsets[v + 1]; ++a) {
      const int f = vf.items[a];
      CHECK((g.F(f, 0) == v || g.F(f, 1) == v || g.F(f, 2) == v));
    }
  CHECK_THROWS_AS(vertex_faces(g.F, 3), std::runtime_error);
}

TEST_CASE("mesh_ops: vertex-edge adjacency lists each edge at both its ends, ascending") {
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(4, 4, 1.0, 1.0).tube());
  const int nv = static_cast<int>(g.V.rows());
  const Pairs E = unique_edges(g.F);
  std::vector<std::array<int, 2>> ends(E.rows());
  for (int e = 0; e < E.rows(); ++e) ends[e] = {E(e, 1), E(e, 0)};  // either order of the ends
  const Csr ve = vertex_edges(ends, nv);
  CHECK(ve.items.size() == 2 * ends.size());
  for (int v = 0; v < nv; ++v) {
    int degree = 0;  // from the faces: a closed-ring neighbour count
    for (int e = 0; e < E.rows(); ++e) degree += E(e, 0) == v || E(e, 1) == v;
    CHECK(ve.count(v) == degree);
    for (int a = ve.offsets[v]; a < ve.offsets[v + 1]; ++a) {
      CHECK((ends[ve.items[a]][0] == v || ends[ve.items[a]][1] == v));
      if (a > ve.offsets[v]) CHECK(ve.items[a - 1] < ve.items[a]);
    }
  }
  CHECK_THROWS_AS(vertex_edges({{0, nv}}, nv), std::runtime_error);
}

TEST_CASE("mesh_ops: triangle frames follow the reference convention") {
  std::mt19937 rng(3);
  std::normal_distribution<double> nd;
  Points3 V(30, 3);
  for (int i = 0; i < V.size(); ++i) V.data()[i] = nd(rng);
  Faces F(10, 3);
  for (int f = 0; f < 10; ++f) F.row(f) << 3 * f, 3 * f + 1, 3 * f + 2;
  const Frames H = triangle_frames(V, F);
  const Points3 N = face_normals(V, F);
  for (int f = 0; f < 10; ++f) {
    Eigen::Matrix3d R;
    R.row(0) = H.row(f).segment<3>(0);
    R.row(1) = H.row(f).segment<3>(3);
    R.row(2) = H.row(f).segment<3>(6);
    CHECK((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-12);
    CHECK(R.determinant() == doctest::Approx(1.0));
    const Eigen::RowVector3d y = (V.row(F(f, 2)) - V.row(F(f, 1))).normalized();
    CHECK((R.row(1) - y).norm() < 1e-12);
    // z = (v2-v1) x (v0-v1) is the face normal (v1-v0) x (v2-v0).
    CHECK((R.row(2) - N.row(f)).norm() < 1e-12);
  }
  // Degenerate triangle: finite (zeros allowed), no NaN.
  Points3 D(3, 3);
  D << 0, 0, 0, 1, 0, 0, 1, 0, 0;
  Faces one(1, 3);
  one << 0, 1, 2;
  CHECK(triangle_frames(D, one).allFinite());
}

TEST_CASE("mesh_ops: dihedral angles of a hinge, including near 0 and near pi") {
  Faces F(2, 3);
  F << 0, 1, 2, 1, 0, 3;  // shared edge 0-1 along x, consistent orientation
  for (double theta : {0.0, 1e-7, 0.3, 1.0, M_PI / 2, 3.0, M_PI - 1e-7}) {
    Points3 V(4, 3);
    V << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -std::cos(theta), std::sin(theta);
    const FacePairs p = adjacent_face_pairs(F);
    REQUIRE(p.size() == 1);
    const Eigen::VectorXd a = dihedral_angles(V, F, p);
    CHECK(a(0) == doctest::Approx(theta).epsilon(1e-9));
  }
}

TEST_CASE("mesh_ops: layer split helpers") {
  const std::vector<int> layer{0, 0, 1, 1, 0};
  const auto vl = vertices_by_layer(layer, 5);
  REQUIRE(vl.size() == 2);
  CHECK(vl[0] == std::vector<int>{0, 1, 4});
  CHECK(vl[1] == std::vector<int>{2, 3});
  Faces F(2, 3);
  F << 0, 1, 4, 2, 3, 4;
  const auto fl = faces_by_layer(layer, F);
  CHECK(fl[0] == std::vector<int>{0});
  CHECK(fl[1] == std::vector<int>{1});
  CHECK(vertices_by_layer({}, 3).size() == 1);
  CHECK_THROWS_AS(vertices_by_layer(layer, 4), std::runtime_error);
}

TEST_CASE("mesh_ops: midpoint subdivision keeps 3-D and UV consistent") {
  const GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(4, 3, 0.8, 0.6).tube());
  const GarmentMesh s = subdivide_midpoint(g);
  CHECK(s.F.rows() == 4 * g.F.rows());
  CHECK(s.V.rows() == g.V.rows() + unique_edges(g.F).rows());
  CHECK(s.UV.rows() == g.UV.rows() + unique_edges(g.FUV).rows());
  CHECK(s.V.topRows(g.V.rows()) == g.V);
  for (int f = 0; f < s.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) CHECK(s.uv_to_vertex[s.FUV(f, k)] == s.F(f, k));
  // Every sub-face has a quarter of its parent's UV area.
  for (int f = 0; f < s.F.rows(); ++f) {
    auto area = [](const Points2& UV, const Faces& F, int t) {
      Eigen::Vector2d a = UV.row(F(t, 0)), b = UV.row(F(t, 1)), c = UV.row(F(t, 2));
      return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    };
    CHECK(area(s.UV, s.FUV, f) == doctest::Approx(area(g.UV, g.FUV, f / 4) / 4).epsilon(1e-12));
  }
}

TEST_CASE("mesh_ops: UV islands numbered left to right, an unused UV vertex on its own") {
  // Two UV triangles far apart in the pattern, the right one first in FUV, and a UV vertex no
  // triangle uses, leftmost of all.
  gdsr::GarmentMesh g;
  g.UV.resize(7, 2);
  g.UV << 5, 0, 6, 0, 5, 1,  // right triangle
      1, 0, 2, 0, 1, 1,      // left triangle
      -3, 0;                 // unused
  g.FUV.resize(2, 3);
  g.FUV << 0, 1, 2, 3, 4, 5;
  CHECK(gdsr::uv_islands(g) == std::vector<int>{2, 2, 2, 1, 1, 1, 0});
  // Joined through a shared UV vertex, the two are one island.
  g.FUV << 0, 1, 3, 3, 4, 5;
  CHECK(gdsr::uv_islands(g) == std::vector<int>{1, 1, 2, 1, 1, 1, 0});
}

#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/geometry/geometry_ad.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "tests/support/loss_test_meshes.hpp"

#include <Eigen/Geometry>
#include <cmath>

using namespace gdsr;
using gdsr_test::bumpy;
using gdsr_test::grid_garment;

namespace {

bool all_finite(const ag::Storage<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// One triangle with UV (0,0),(1,0),(0,1) (metres) and the given 3-D corners.
MeshTopology one_triangle(Points3& X, const Vec3& a, const Vec3& b, const Vec3& c) {
  GarmentMesh g;
  g.V.resize(3, 3);
  g.V.row(0) = a.transpose();
  g.V.row(1) = b.transpose();
  g.V.row(2) = c.transpose();
  g.F.resize(1, 3);
  g.F << 0, 1, 2;
  g.UV.resize(3, 2);
  g.UV << 0, 0, 1, 0, 0, 1;
  g.FUV = g.F;
  X = g.V;
  return make_topology(g);
}

// A random-weighted scalar of a geometry output, for gradient checks.
using GeoFn = std::function<ag::Tensord(const ag::Tensord&, const MeshTopology&)>;

ag::GradCheckResult check_geo(const GeoFn& fn, const Points3& X, const MeshTopology& t, double scale) {
  ag::GradCheckOptions opt;
  // gradcheck's step is h = step * max |x|, relative to the input already; at x1e3 the mesh
  // sits at x ~ 1000 (see below), where 1e-7 keeps h near 1e-6 of the mesh size.
  opt.step = scale <= 1 ? 1e-6 : 1e-7;
  return ag::gradcheck([&](const std::vector<ag::Tensord>& in) { return fn(in[0], t); }, {to_tensor<double>(X)}, opt);
}

}  // namespace

TEST_CASE("geometry_ad: deformation gradient of a stretched and a sheared triangle") {
  Points3 X;
  MeshTopology t = one_triangle(X, {0, 0, 0}, {2, 0, 0}, {0, 1, 0});
  ag::Tensord m = strain_measures(to_tensor<double>(X), t);
  CHECK(m.at(0, 0) == doctest::Approx(2.0));  // |F_u|: stretched by 2 along u
  CHECK(m.at(0, 1) == doctest::Approx(1.0));  // |F_v|
  CHECK(std::abs(m.at(0, 2)) < 1e-12);        // no shear
  // The same deformation rotated and translated in 3-D: identical measures.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Points3 Y = (X * R.transpose()).rowwise() + Eigen::RowVector3d(0.3, -1, 2);
  ag::Tensord mr = strain_measures(to_tensor<double>(Y), t);
  for (int k = 0; k < 3; ++k) CHECK(mr.at(0, k) == doctest::Approx(m.at(0, k)).epsilon(1e-12));
  // Shear: v edge tilted by 45 degrees.
  t = one_triangle(X, {0, 0, 0}, {1, 0, 0}, {1, 1, 0});
  m = strain_measures(to_tensor<double>(X), t);
  CHECK(m.at(0, 0) == doctest::Approx(1.0));
  CHECK(m.at(0, 1) == doctest::Approx(std::sqrt(2.0)));
  CHECK(m.at(0, 2) == doctest::Approx(1.0 / std::sqrt(2.0)));
  UVGradient<double> g = uv_gradient(to_tensor<double>(X), t);
  CHECK(g.Fv.at(0, 0) == doctest::Approx(1.0));
  CHECK(g.Fv.at(0, 1) == doctest::Approx(1.0));
}

TEST_CASE("geometry_ad: normals agree with mesh_ops and point along +z on a flat grid") {
  GarmentMesh g = grid_garment(gdsr_test::GridSpec::spaced(6, 0.01));
  const MeshTopology t = make_topology(g);
  ag::Tensord n = vertex_normals(to_tensor<double>(g.V), t);
  for (int v = 0; v < 36; ++v) CHECK(n.at(v, 2) == doctest::Approx(1.0));
  const Points3 X = bumpy(g.V, 0.3, 1.0);
  ag::Tensord nv = vertex_normals(to_tensor<double>(X), t);
  ag::Tensord nf = face_normals(to_tensor<double>(X), t);
  const Points3 rv = vertex_normals(X, g.F), rf = face_normals(X, g.F);
  CHECK((nv.mat() - rv).cwiseAbs().maxCoeff() < 1e-9);
  CHECK((nf.mat() - rf).cwiseAbs().maxCoeff() < 1e-9);
  ag::Tensord a = dihedral_angles(to_tensor<double>(X), t);
  const Eigen::VectorXd ra = dihedral_angles(X, g.F, adjacent_face_pairs(g.F));
  REQUIRE(a.rows() == ra.size());
  CHECK((a.mat().col(0) - ra).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(ra.maxCoeff() > 0.01);
}

TEST_CASE("geometry_ad: smoothness residual is zero at the interior of a flat regular grid") {
  GarmentMesh g = grid_garment(gdsr_test::GridSpec::spaced(7, 0.02));
  const MeshTopology t = make_topology(g);
  const ag::Tensord r = smoothness_residual(to_tensor<double>(g.V), t);
  double interior = 0, boundary = 0;
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 7; ++i) {
      const double e = r.mat().row(j * 7 + i).norm();
      if (i > 0 && j > 0 && i < 6 && j < 6)
        interior = std::max(interior, e);
      else
        boundary = std::max(boundary, e);
    }
  CHECK(interior < 1e-15);
  CHECK(boundary > 1e-3);  // boundary vertices are off their centroid mean: the test can fail
  Points3 X = g.V;
  X(3 * 7 + 3, 2) = 0.01;  // lift one interior vertex
  const ag::Tensord r2 = smoothness_residual(to_tensor<double>(X), t);
  CHECK(r2.at(3 * 7 + 3, 2) == doctest::Approx(0.01 * 2.0 / 3.0));  // each adjacent centroid rises by 0.01/3
  CHECK(smoothness(to_tensor<double>(X), t).item() > smoothness(to_tensor<double>(g.V), t).item());
}

TEST_CASE("geometry_ad: dihedral angles at 0, pi/2 and pi, with finite zero gradients at the kinks") {
  // Two triangles sharing the edge (0,1): flat, folded by 90 degrees, folded flat onto each other.
  auto pair_mesh = [](double angle) {
    GarmentMesh g;
    g.V.resize(4, 3);
    g.V << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -std::cos(angle), std::sin(angle);
    g.F.resize(2, 3);
    g.F << 0, 1, 2, 1, 0, 3;
    g.UV.resize(4, 2);
    g.UV << 0, 0, 1, 0, 0.5, 1, 0.5, -1;
    g.FUV = g.F;
    return g;
  };
  const double expect[3] = {0.0, M_PI / 2, M_PI};
  const double fold[3] = {0.0, M_PI / 2, M_PI};
  for (int c = 0; c < 3; ++c) {
    GarmentMesh g = pair_mesh(fold[c]);
    // angle = pi: the fourth vertex lands exactly on the second triangle's side.
    if (c == 2) g.V.row(3) << 0.5, 1, 0;
    const MeshTopology t = make_topology(g);
    ag::Tensord X = to_tensor<double>(g.V);
    X.set_requires_grad(true);
    ag::Tensord a = dihedral_angles(X, t);
    CHECK(a.item() == doctest::Approx(expect[c]).epsilon(1e-9));
    ag::sum(a).backward();
    REQUIRE(X.has_grad());
    CHECK(all_finite(X.grad()));
    double gmax = 0;
    for (double v : X.grad()) gmax = std::max(gmax, std::abs(v));
    if (c == 1)
      CHECK(gmax > 0.1);  // smooth there: a real gradient
    else
      CHECK(gmax == 0.0);  // kink of the unsigned angle: subgradient 0
  }
}

TEST_CASE("geometry_ad: float64 gradient checks of every term on a bumpy grid, metres, x1e-3, x1e3") {
  const GarmentMesh g0 = grid_garment(gdsr_test::GridSpec::spaced(5, 0.03));
  for (double scale : {1.0, 1e-3, 1e3}) {
    CAPTURE(scale);
    GarmentMesh g = g0;
    g.V *= scale;
    g.UV *= scale;
    const MeshTopology t = make_topology(g);
    // At x1e3 the mesh is also moved to x ~ +1000 (every term is translation invariant), a
    // placement that also exercises round-off of coordinates far from the origin.
    const Points3 X = bumpy(g0.V, 0.4, scale, 1).array() + (scale > 1 ? 1000.0 : 0.0);
    const std::vector<std::pair<const char*, GeoFn>> fns = {
        {"face_normals", [](const ag::Tensord& x, const MeshTopology& t) { return face_normals(x, t); }},
        {"vertex_normals", [](const ag::Tensord& x, const MeshTopology& t) { return vertex_normals(x, t); }},
        {"strain", [](const ag::Tensord& x, const MeshTopology& t) { return strain_measures(x, t); }},
        {"smoothness", [](const ag::Tensord& x, const MeshTopology& t) { return smoothness(x, t); }},
        {"dihedral", [](const ag::Tensord& x, const MeshTopology& t) { return dihedral_angles(x, t); }},
    };
    for (const auto& [name, fn] : fns) {
      INFO(name);
      const ag::GradCheckResult r = check_geo(fn, X, t, scale);
      INFO(r.report());
      CHECK(r.max_rel_error < 1e-6);
    }
  }
}

TEST_CASE("geometry_ad: degenerate triangles give finite values and gradients") {
  GarmentMesh g = grid_garment(gdsr_test::GridSpec::spaced(4, 0.05));
  Points3 X = bumpy(g.V, 0.2, 1.0, 2);
  // Face 0 (a, b, c) collapsed to a point; face 3's corners made collinear.
  X.row(g.F(0, 1)) = X.row(g.F(0, 0));
  X.row(g.F(0, 2)) = X.row(g.F(0, 0));
  X.row(g.F(3, 2)) = 0.5 * (X.row(g.F(3, 0)) + X.row(g.F(3, 1)));
  const MeshTopology t = make_topology(g);
  const std::vector<GeoFn> fns = {
      [](const ag::Tensord& x, const MeshTopology& t) { return face_normals(x, t); },
      [](const ag::Tensord& x, const MeshTopology& t) { return vertex_normals(x, t); },
      [](const ag::Tensord& x, const MeshTopology& t) { return strain_measures(x, t); },
      [](const ag::Tensord& x, const MeshTopology& t) { return smoothness(x, t); },
      [](const ag::Tensord& x, const MeshTopology& t) { return dihedral_angles(x, t); },
  };
  for (size_t k = 0; k < fns.size(); ++k) {
    CAPTURE(k);
    ag::Tensord x = to_tensor<double>(X);
    x.set_requires_grad(true);
    const ag::Tensord y = fns[k](x, t);
    CHECK(all_finite(y.values()));
    ag::sum(y).backward();
    REQUIRE(x.has_grad());
    CHECK(all_finite(x.grad()));
  }
  // The zero-area face's normal is 0 (not NaN); smoothness stays smooth there: exact check.
  const ag::Tensord fn = face_normals(to_tensor<double>(X), t);
  CHECK(fn.mat().row(0).norm() == 0.0);
  const ag::GradCheckResult r =
      check_geo([](const ag::Tensord& x, const MeshTopology& t) { return smoothness(x, t); }, X, t, 1.0);
  INFO(r.report());
  CHECK(r.max_rel_error < 1e-6);
}

TEST_CASE("geometry_ad: collinear UV triangles are skipped by the strain term") {
  GarmentMesh g = grid_garment(gdsr_test::GridSpec::spaced(3, 0.1));
  g.UV.row(1) << 0.05, 0.05;  // onto the line from UV 0 to UV 4: face (0, 1, 4) collinear
  const MeshTopology t = make_topology(g);
  CHECK(t.num_degenerate_uv >= 1);
  CHECK(static_cast<int>(t.strain_faces.size()) + t.num_degenerate_uv == t.num_faces);
  const ag::Tensord m = strain_measures(to_tensor<double>(bumpy(g.V, 0.2, 1.0)), t);
  CHECK(m.rows() == static_cast<int64_t>(t.strain_faces.size()));
  CHECK(all_finite(m.values()));
}

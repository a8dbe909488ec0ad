// Appendix-B stretch/shear energies and the longest edge (gdsr/geometry/strain.hpp) against
// closed forms.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "gdsr/geometry/strain.hpp"
#include "tests/support/data_fixtures.hpp"

TEST_CASE("strain energies: zero for the flat rest sheet, (s - 1)^2 for a uniform stretch") {
  const gdsr::GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(3, 3, 0.2, 0.2));
  const gdsr::StrainEnergies rest = gdsr::strain_energies(g, g.V);
  CHECK(rest.E_u == doctest::Approx(0).epsilon(1e-12));
  CHECK(rest.E_uv == doctest::Approx(0).epsilon(1e-12));
  gdsr::Points3 s = g.V;
  s.col(0) *= 1.5;
  const gdsr::StrainEnergies st = gdsr::strain_energies(g, s);
  CHECK(st.E_u == doctest::Approx(0.25));
  CHECK(st.E_v == doctest::Approx(0).epsilon(1e-12));
}

TEST_CASE("strain energies: the stretched part of E_u and E_v counts only fibres longer than the pattern") {
  // x stretched by 1.5 and y shortened to 0.8: E_u = 0.25 all stretched, E_v = 0.04 all
  // compressed; then y stretched by 1.2 instead: E_v = 0.04 all stretched.
  const gdsr::GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(3, 3, 0.2, 0.2));
  gdsr::Points3 s = g.V;
  s.col(0) *= 1.5;
  s.col(1) *= 0.8;
  const gdsr::StrainEnergies a = gdsr::strain_energies(g, s);
  CHECK(a.E_u == doctest::Approx(0.25));
  CHECK(a.E_u_stretched == doctest::Approx(0.25));
  CHECK(a.E_v == doctest::Approx(0.04));
  CHECK(a.E_v_stretched == doctest::Approx(0).epsilon(1e-12));
  s.col(1) *= 1.2 / 0.8;
  const gdsr::StrainEnergies b = gdsr::strain_energies(g, s);
  CHECK(b.E_v_stretched == doctest::Approx(0.04));
  CHECK(b.E_v == doctest::Approx(0.04));
}

TEST_CASE("strain energies: shear (w_u . w_v)^2 of a simple shear / degenerate UV triangles left out") {
  gdsr::GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(3, 3, 0.2, 0.2));
  gdsr::Points3 s = g.V;
  s.col(0) += 0.5 * g.V.col(1);  // x += 0.5 y: w_u = (1, 0, 0), w_v = (0.5, 1, 0)
  const gdsr::StrainEnergies e = gdsr::strain_energies(g, s);
  CHECK(e.E_u == doctest::Approx(0).epsilon(1e-12));
  CHECK(e.E_v == doctest::Approx((std::sqrt(1.25) - 1) * (std::sqrt(1.25) - 1)));
  CHECK(e.E_uv == doctest::Approx(0.25));
  // Collapse one UV triangle onto a line: it is skipped, the others keep the same means.
  g.FUV.row(0) << g.FUV(0, 0), g.FUV(0, 0), g.FUV(0, 2);
  const gdsr::StrainEnergies d = gdsr::strain_energies(g, s);
  CHECK(std::isfinite(d.E_u));
  CHECK(d.E_uv == doctest::Approx(0.25));
  CHECK_THROWS_WITH(gdsr::strain_energies(g, s.topRows(3)), doctest::Contains("3 positions"));
}

TEST_CASE("strain: the longest edge over its pattern length finds one dragged-out vertex") {
  // 3x3 quads over 0.2 m: edges a = 0.2 / 3 along u and v, diagonals a sqrt 2.
  const gdsr::GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(3, 3, 0.2, 0.2));
  const double a = 0.2 / 3;
  CHECK(gdsr::max_edge_stretch(g, g.V) == doctest::Approx(1).epsilon(1e-12));
  gdsr::Points3 s = g.V;
  s.col(0) *= 1.5;
  CHECK(gdsr::max_edge_stretch(g, s) == doctest::Approx(1.5).epsilon(1e-12));
  // Pull the inner vertex at (a, a) 3a out of the sheet: its edges along u and v become
  // sqrt(a^2 + 9 a^2) = a sqrt 10 long, its diagonals sqrt(11 / 2) times theirs.
  int inner = -1;
  for (int v = 0; v < g.V.rows(); ++v)
    if (std::abs(g.V(v, 0) - a) < 1e-9 && std::abs(g.V(v, 1) - a) < 1e-9) inner = v;
  REQUIRE(inner >= 0);
  gdsr::Points3 d = g.V;
  d(inner, 2) += 3 * a;
  CHECK(gdsr::max_edge_stretch(g, d) == doctest::Approx(std::sqrt(10.0)).epsilon(1e-12));
  // The vertices of the edges past 2x: the dragged vertex and its eight neighbours (the four
  // quads around it are all split through it); past 3x, only the edges along u and v (3.16x).
  const std::vector<int> torn = gdsr::overstretched_vertices(g, d, 2);
  CHECK(torn.size() == 9);
  CHECK(std::find(torn.begin(), torn.end(), inner) != torn.end());
  CHECK(gdsr::overstretched_vertices(g, d, 3).size() == 5);
  CHECK(gdsr::overstretched_vertices(g, s, 2).empty());
  d(inner, 0) = std::numeric_limits<double>::quiet_NaN();  // a NaN does not read as intact cloth
  CHECK(std::isnan(gdsr::max_edge_stretch(g, d)));
  CHECK_THROWS_WITH(gdsr::max_edge_stretch(g, s.topRows(3)), doctest::Contains("3 positions"));
}

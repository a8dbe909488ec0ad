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

TEST_CASE("strain energies by pattern piece: UV islands left to right, each piece's own means") {
  // Two unit squares welded along the edge x = 1 in 3-D, cut apart in the pattern: the right
  // square's UV island lies at x 2..3, the left one's at 0..1. The faces list the right square
  // first, so the numbering comes from the layout, not the face order.
  gdsr::GarmentMesh g;
  g.V.resize(6, 3);
  g.V << 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0;
  g.UV.resize(8, 2);
  g.UV << 2, 0, 3, 0, 3, 1, 2, 1,  // right square: 3-D vertices 1, 2, 5, 4
      0, 0, 1, 0, 1, 1, 0, 1;      // left square: 0, 1, 4, 3
  g.uv_to_vertex = {1, 2, 5, 4, 0, 1, 4, 3};
  g.F.resize(4, 3);
  g.F << 1, 2, 5, 1, 5, 4, 0, 1, 4, 0, 4, 3;
  g.FUV.resize(4, 3);
  g.FUV << 0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7;
  const std::vector<int> piece = gdsr::pattern_pieces(g);
  CHECK(piece == std::vector<int>{1, 1, 0, 0});
  // The right square shortened to 0.8 across, the left one left at rest: only piece 1 is
  // strained, all of it in compression; the whole garment's mean is the face-weighted mean.
  gdsr::Points3 X = g.V;
  X(2, 0) = X(5, 0) = 1.8;
  const auto by = gdsr::strain_energies_by_piece(g, X, piece);
  REQUIRE(by.size() == 2);
  CHECK(by[0].faces == 2);
  CHECK(by[0].E_u == doctest::Approx(0).epsilon(1e-12));
  CHECK(by[1].faces == 2);
  CHECK(by[1].E_u == doctest::Approx(0.04));
  CHECK(by[1].E_u_stretched == doctest::Approx(0).epsilon(1e-12));
  CHECK(by[1].E_v == doctest::Approx(0).epsilon(1e-12));
  const gdsr::StrainEnergies all = gdsr::strain_energies(g, X);
  CHECK(all.faces == 4);
  CHECK(all.E_u == doctest::Approx(0.02));
  // Piece indices that do not match the faces are refused.
  CHECK_THROWS(gdsr::strain_energies_by_piece(g, X, {0, 1}));
  CHECK_THROWS(gdsr::strain_energies_by_piece(g, X, {0, 0, -1, 0}));
}

TEST_CASE("strain: each triangle's fibre lengths over the pattern's, NaN where the UV triangle is degenerate") {
  // x *= 1.5, y *= 0.8: every triangle's u fibre is 1.5 times its pattern length, its v fibre 0.8.
  gdsr::GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec(3, 3, 0.2, 0.2));
  gdsr::Points3 s = g.V;
  s.col(0) *= 1.5;
  s.col(1) *= 0.8;
  g.FUV.row(0) << g.FUV(0, 0), g.FUV(0, 0), g.FUV(0, 2);
  const std::vector<gdsr::Vec2> w = gdsr::fibre_stretch(g, s);
  REQUIRE(w.size() == static_cast<size_t>(g.F.rows()));
  CHECK(std::isnan(w[0].x()));
  for (size_t f = 1; f < w.size(); ++f) {
    CHECK(w[f].x() == doctest::Approx(1.5));
    CHECK(w[f].y() == doctest::Approx(0.8));
  }
  CHECK_THROWS_WITH(gdsr::fibre_stretch(g, s.topRows(3)), doctest::Contains("3 positions"));
}

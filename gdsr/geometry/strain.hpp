// Stretch and shear of a garment against its flat sewing pattern (paper, appendix B): per
// triangle, w = [w_u w_v] = Ds Dm^-1 is the deformation gradient from UV (metres) to 3-D
// (metres), and
//   E_u = (|w_u| - 1)^2,  E_v = (|w_v| - 1)^2,  E_uv = (w_u . w_v)^2   (dimensionless),
// averaged over triangles. The one implementation used by the simulator's metrics and by
// `gdsr eval`, so their figures agree. E_u and E_v are split by the sign of |w| - 1 into the
// stretched part (fibres longer than in the pattern, resisted by the fabric's stretch
// stiffness) and the compressed part (shorter: how a mesh takes up folds finer than itself).
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <vector>

namespace gdsr {

struct StrainEnergies {
  double E_u = 0, E_v = 0, E_uv = 0;  // means over triangles (dimensionless)
  // The stretched part of E_u and E_v: means of max(|w_u| - 1, 0)^2, max(|w_v| - 1, 0)^2.
  double E_u_stretched = 0, E_v_stretched = 0;
  int faces = 0;  // triangles averaged over (those with a non-degenerate UV triangle)
};

// X: positions of g's welded vertices (V x 3, metres), triangles g.F with UV triangles g.FUV.
// Triangles whose UV area is degenerate (|det Dm| <= 1e-8 x longest UV edge^2, a scale-free
// test) carry no deformation gradient and are left out of the means.
StrainEnergies strain_energies(const GarmentMesh& g, const Points3& X);

// Per triangle, the lengths |w_u| and |w_v| of its u and v fibres over their pattern lengths
// (1: as cut, < 1 compressed, > 1 stretched); NaN for a triangle whose UV triangle is
// degenerate (see above).
std::vector<Vec2> fibre_stretch(const GarmentMesh& g, const Points3& X);

// The pieces of the flat pattern (its panels): per triangle, the index of its UV island
// (gdsr::uv_islands, numbered left to right as the pattern lays its panels out).
std::vector<int> pattern_pieces(const GarmentMesh& g);

// strain_energies over each piece's triangles alone: element k for piece k of `piece`
// (pattern_pieces(g)); a piece whose UV triangles are all degenerate gets zeros.
std::vector<StrainEnergies> strain_energies_by_piece(const GarmentMesh& g, const Points3& X,
                                                     const std::vector<int>& piece);

// Longest edge of X over its length in the sewing pattern (dimensionless: 1 at rest, 2 for an
// edge at twice its length). Woven fabric tears long before 2x, so a larger value marks cloth
// that a contact dragged out of the garment: a few vertices that the means above hide (a
// forearm pushed single 10 mm t-shirt vertices 60 cm along the arm, edges 6x, while the mean
// E_u stayed below 0.01). Edges of the triangles strain_energies leaves out do not count; 0
// for a garment without faces, NaN when a position is not finite.
double max_edge_stretch(const GarmentMesh& g, const Points3& X);

// The welded vertices at the ends of the edges max_edge_stretch counts that are longer than
// `limit` times their pattern length, sorted, each once: whether a torn frame is cloth dragged
// out of the garment here and there or one vertex overstretched again and again.
std::vector<int> overstretched_vertices(const GarmentMesh& g, const Points3& X, double limit);

}  // namespace gdsr

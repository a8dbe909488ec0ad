// Long-range attachments (Kim, Chentanez and Mueller-Fischer 2012): every free vertex of a
// pinned garment is tethered to its nearest pinned vertex and may not be farther from it
// than its rest distance along the cloth (times 1 + allowed stretch).
//
// Why: a Gauss-Seidel solver with a fixed number of passes converges more slowly on finer
// meshes (a 10 mm mesh has 3x the vertices along the hanging direction of a 30 mm one), so
// without help the same fabric hangs visibly longer at HR than at LR. The tether bounds the
// stretch of the whole hanging column in one step, whatever the resolution, and never acts
// on cloth that is compressed or folded (it is one-sided).
//
// Rest distance: the nearest pin is found by Dijkstra over the mesh edges (lengths from the
// flat pattern). The distance is the straight line in the flat pattern when both vertices
// have copies in the same UV chart and that line is not much shorter than the edge path
// (edge paths zig-zag and overestimate by up to ~15%); otherwise the edge-path length.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <vector>

namespace sim {

struct Tether {
  int v;        // free vertex
  int pin;      // pinned vertex it hangs from
  double rest;  // metres, rest distance along the cloth
};

// One tether per free vertex that the pinned vertices reach through the mesh (none when
// `pinned` is empty). Throws gdsr::Error on an out-of-range pinned index.
std::vector<Tether> make_tethers(const gdsr::GarmentMesh& m, const std::vector<int>& pinned);

// Moves each free vertex that is farther than rest * (1 + max_stretch) from its pin back
// onto that sphere (the pin does not move). Returns how many were moved.
int project_tethers(const std::vector<Tether>& tethers, double max_stretch, gdsr::Points3& x);

}  // namespace sim

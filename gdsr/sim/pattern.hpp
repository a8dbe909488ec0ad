// Sewing patterns: flat panels (2-D polygons in metres, laid out without overlap in one
// plane, which IS the UV layout) plus seams that join two panel edges. mesh_pattern turns a
// pattern into a GarmentMesh at a target particle distance: boundary edges are split to the
// target length first (both sides of a seam get the same number of vertices), then each
// panel is filled with CGAL's constrained Delaunay mesher (no boundary refinement), so the
// outline is the same polygon at every resolution. Seam copies weld into one 3-D vertex.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <functional>
#include <string>
#include <vector>

namespace sim {

struct Panel {
  std::string name;
  std::vector<gdsr::Vec2> outline;  // polygon corners in metres, counter-clockwise, not closed
};

// Seam between edge (a_edge, a_edge+1) of panel a and edge (b_edge, b_edge+1) of panel b.
// reversed = true (the usual case for two counter-clockwise panels seen from the same side):
// the start of edge a meets the end of edge b.
struct Seam {
  int a_panel = 0, a_edge = 0;
  int b_panel = 0, b_edge = 0;
  bool reversed = true;
};

struct Pattern {
  std::vector<Panel> panels;
  std::vector<Seam> seams;
};

// Throws gdsr::Error (one line) for degenerate or clockwise panels, overlapping or
// self-intersecting panels, and seams naming missing edges.
void validate_pattern(const Pattern& p);

struct PatternMesh {
  gdsr::GarmentMesh mesh;        // V is zero (to be placed), UV = pattern coordinates (metres)
  std::vector<int> uv_panel;     // UV vertex -> panel index
  std::vector<int> uv_boundary;  // UV vertex -> panel edge index it lies on, -1 inside
};

// Meshes every panel at the target particle distance (metres, > 0) and welds the seams.
PatternMesh mesh_pattern(const Pattern& p, double particle_distance);

// Sets mesh.V from a per-panel placement (panel index, pattern point in metres) -> 3-D point
// in metres; a welded vertex gets the mean of its UV copies' placements.
void place_pattern(PatternMesh& pm, const std::function<gdsr::Vec3(int panel, const gdsr::Vec2& uv)>& place);

// Polygon helpers (metres).
double polygon_area(const std::vector<gdsr::Vec2>& poly);  // signed, > 0 counter-clockwise
// Arc polyline from angle a0 to a1 (radians) around c with radius r, `n` segments, n+1 points.
std::vector<gdsr::Vec2> arc_points(const gdsr::Vec2& c, double r, double a0, double a1, int n);

}  // namespace sim

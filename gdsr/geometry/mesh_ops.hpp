// Mesh geometry and integer topology in double precision (no gradients): normals, edge
// sets, ring-2 pairs, adjacency, local triangle frames, dihedral angles, layer splits,
// midpoint subdivision. Positions in metres; index matrices are row-major.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <Eigen/Core>
#include <array>
#include <vector>

namespace gdsr {

using Pairs = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;  // P x 2 index pairs

// Unit face normals, F x 3 ((v1-v0) x (v2-v0) normalised); zero for degenerate faces.
Points3 face_normals(const Points3& V, const Faces& F);

// Area-weighted vertex normals, V x 3 (sum of the unnormalised face cross products of the
// adjacent faces, normalised); zero for isolated vertices.
Points3 vertex_normals(const Points3& V, const Faces& F);

// Unique undirected edges, E x 2 with row(e) = (i, j), i < j, sorted lexicographically.
Pairs unique_edges(const Faces& F);

// Vertex pairs at graph distance exactly 2 along the edges of F, P x 2 with i < j, sorted.
Pairs ring2_pairs(const Faces& F, int num_vertices);

// Compressed adjacency lists: the items of vertex v are items[offsets[v] .. offsets[v+1]).
struct Csr {
  std::vector<int> offsets;  // num_vertices + 1
  std::vector<int> items;
  int count(int v) const { return offsets[v + 1] - offsets[v]; }
};
Csr build_csr(std::vector<std::vector<int>>&& lists);      // list v becomes the items of vertex v, in order
Csr vertex_faces(const Faces& F, int num_vertices);       // faces around each vertex, ascending
Csr vertex_neighbours(const Faces& F, int num_vertices);  // ring-1 vertices, ascending
// Edges at each vertex, ascending: edge e (ends[e], any two vertices) is an item of both its ends.
Csr vertex_edges(const std::vector<std::array<int, 2>>& ends, int num_vertices);

// Pairs of faces sharing an edge (manifold interior edges; an edge with more than two faces
// yields a pair for each consecutive pair of faces). For pair p: faces(p) = (f0, f1),
// edge(p) = the shared vertices (i, j), opposite(p) = the vertex of f0 and the vertex of f1
// not on the edge.
struct FacePairs {
  Pairs faces;
  Pairs edge;
  Pairs opposite;
  int size() const { return static_cast<int>(faces.rows()); }
};
FacePairs adjacent_face_pairs(const Faces& F);

// Vertices on a boundary edge (an edge with exactly one face), ascending.
std::vector<int> boundary_vertices(const Faces& F);

// The UV islands of a flat pattern (its panels): per UV vertex, the index of its island (UV
// vertices joined through the UV triangles FUV), islands numbered by their smallest UV x, so in
// the order the pattern lays its panels out from left to right (ties: the lower vertex).
std::vector<int> uv_islands(const GarmentMesh& g);

// Mean length of the unique edges (metres); 0 for a mesh without edges.
double mean_edge_length(const Points3& V, const Faces& F);

// Local frame of each triangle (v0, v1, v2), stored as F x 9 rows (x, y, z) with
// y = normalize(v2 - v1, eps L), z = normalize((v2 - v1) x (v0 - v1), eps L^2), x = y x z;
// normalize(a, e) = a / max(|a|, e), L = sqrt(|v2 - v1|^2 + |v0 - v1|^2). eps is relative to
// the triangle's own size (the reference's absolute 1e-6 is not scale-free); a triangle
// collapsed to a point gets the zero frame. The plain-double twin of triangle_frames_ad.
using Frames = Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor>;
Frames triangle_frames(const Points3& V, const Faces& F, double eps = 1e-3);

// Dihedral angle per face pair: atan2(|n0 x n1|, n0 . n1) in radians, 0 for a flat pair,
// up to pi for a folded one. Uses unit face normals (zero normals give angle 0).
Eigen::VectorXd dihedral_angles(const Points3& V, const Faces& F, const FacePairs& pairs);

// Layer helpers. `layer` holds one layer id per vertex (empty = one layer).
std::vector<std::vector<int>> vertices_by_layer(const std::vector<int>& layer, int num_vertices);
// Face layer = layer of its first vertex; faces grouped per layer.
std::vector<std::vector<int>> faces_by_layer(const std::vector<int>& layer, const Faces& F);

// Midpoint subdivision (each triangle -> 4) of a garment in 3-D and in UV consistently:
// the original vertices keep their indices (0..V-1, 0..UV-1); edge midpoints follow. Face
// 4f+k of the result lies inside face f (k = 0,1,2 the corner triangles at v0,v1,v2, k = 3
// the middle one). Layers are copied (a midpoint takes its first endpoint's layer).
GarmentMesh subdivide_midpoint(const GarmentMesh& g);

}  // namespace gdsr

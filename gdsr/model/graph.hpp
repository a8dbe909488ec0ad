// The per-garment static graph of the LR mesh used by H and E, and the per-frame layer
// edges of multi-layer garments. Integer topology plus rest lengths (metres); built once.
#pragma once

#include "autograd/tensor.hpp"
#include "gdsr/geometry/mesh.hpp"

#include <vector>

namespace gdsr {

struct GarmentGraph {
  int num_vertices = 0;
  Faces F;  // LR triangles x 3
  // Ring-1 mesh edges, both directions: directed edge k goes src[k] -> dst[k]; the edge and
  // its reverse are 2i and 2i+1. Messages are summed at src.
  ag::Index ring1_src, ring1_dst;
  std::vector<double> ring1_rest;  // rest length per directed ring-1 edge, metres
  // Ring-2 pairs (graph distance exactly 2), both directions, same layout.
  ag::Index ring2_src, ring2_dst;
  // Face corners flattened row-major: corner 3f+k is vertex F(f,k) (3F entries).
  ag::Index face_corners;
  std::vector<int> layer;  // vertex -> cloth layer; empty for one layer
  int num_layers = 1;

  int num_faces() const { return static_cast<int>(F.rows()); }
  int64_t ring1_size() const { return static_cast<int64_t>(ring1_src.size()); }
  int64_t ring2_size() const { return static_cast<int64_t>(ring2_src.size()); }
};

// Topology and rest lengths from the canonical (rest) LR garment (lr.V, lr.F, lr.layer).
// Throws for an empty mesh or face indices out of range.
GarmentGraph build_graph(const GarmentMesh& lr);

// Directed layer edges of one frame: vertex pairs on different layers closer than sigma_l
// (metres) in `positions` (V x 3), both directions, sorted by (src, dst). Empty (and no
// k-d tree built) for a single-layer garment.
struct LayerEdges {
  ag::Index src, dst;
  int64_t size() const { return static_cast<int64_t>(src.size()); }
};
LayerEdges find_layer_edges(const GarmentGraph& g, const Points3& positions, double sigma_l);

}  // namespace gdsr

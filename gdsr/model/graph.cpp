#include "gdsr/model/graph.hpp"

#include "gdsr/error.hpp"

#include "gdsr/geometry/mesh_ops.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace gdsr {

GarmentGraph build_graph(const GarmentMesh& lr) {
  const int V = static_cast<int>(lr.V.rows());
  if (V == 0 || lr.F.rows() == 0) gdsr::fail("graph", "empty LR mesh");
  if (lr.F.minCoeff() < 0 || lr.F.maxCoeff() >= V) gdsr::fail("graph", "face index out of range");
  if (!lr.layer.empty() && static_cast<int>(lr.layer.size()) != V)
    gdsr::fail("graph", "layer list size differs from the vertex count");
  GarmentGraph g;
  g.num_vertices = V;
  g.F = lr.F;
  const Pairs e1 = unique_edges(lr.F);
  for (int k = 0; k < e1.rows(); ++k) {
    const int i = e1(k, 0), j = e1(k, 1);
    const double rest = (lr.V.row(i) - lr.V.row(j)).norm();
    g.ring1_src.push_back(i), g.ring1_dst.push_back(j), g.ring1_rest.push_back(rest);
    g.ring1_src.push_back(j), g.ring1_dst.push_back(i), g.ring1_rest.push_back(rest);
  }
  const Pairs e2 = ring2_pairs(lr.F, V);
  for (int k = 0; k < e2.rows(); ++k) {
    g.ring2_src.push_back(e2(k, 0)), g.ring2_dst.push_back(e2(k, 1));
    g.ring2_src.push_back(e2(k, 1)), g.ring2_dst.push_back(e2(k, 0));
  }
  g.face_corners.resize(static_cast<size_t>(3 * lr.F.rows()));
  for (int f = 0; f < lr.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) g.face_corners[3 * f + k] = lr.F(f, k);
  g.num_layers = 1;
  if (!lr.layer.empty()) {
    std::vector<int> ids = lr.layer;
    std::sort(ids.begin(), ids.end());
    g.num_layers = static_cast<int>(std::unique(ids.begin(), ids.end()) - ids.begin());
    if (g.num_layers > 1) g.layer = lr.layer;
  }
  return g;
}

LayerEdges find_layer_edges(const GarmentGraph& g, const Points3& positions, double sigma_l) {
  LayerEdges out;
  if (g.num_layers <= 1) return out;
  if (positions.rows() != g.num_vertices)
    gdsr::fail("graph", "find_layer_edges got " + std::to_string(positions.rows()) + " positions for " +
                            std::to_string(g.num_vertices) + " vertices");
  using Tree = nanoflann::KDTreeEigenMatrixAdaptor<Points3, 3, nanoflann::metric_L2_Simple>;
  Tree tree(3, std::cref(positions), 10);
  const double r2 = sigma_l * sigma_l;
  std::vector<std::pair<Eigen::Index, double>> hits;
  nanoflann::SearchParams params;
  params.sorted = false;
  for (int i = 0; i < g.num_vertices; ++i) {
    hits.clear();
    const double q[3] = {positions(i, 0), positions(i, 1), positions(i, 2)};
    tree.index->radiusSearch(q, r2, hits, params);
    std::vector<int> js;
    for (const auto& h : hits) {
      const int j = static_cast<int>(h.first);
      if (g.layer[j] != g.layer[i] && h.second < r2) js.push_back(j);
    }
    std::sort(js.begin(), js.end());
    for (int j : js) out.src.push_back(i), out.dst.push_back(j);
  }
  return out;
}

}  // namespace gdsr

#include "gdsr/sim/cloth_tethers.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/mesh_ops.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

namespace sim {

std::vector<Tether> make_tethers(const gdsr::GarmentMesh& m, const std::vector<int>& pinned) {
  const int nv = static_cast<int>(m.V.rows());
  if (pinned.empty()) return {};
  std::vector<char> is_pin(nv, 0);
  for (int p : pinned) {
    if (p < 0 || p >= nv) gdsr::fail("sim/cloth_tethers", "pinned vertex " + std::to_string(p) + " out of range");
    is_pin[p] = 1;
  }
  // Edge graph with flat-pattern lengths.
  std::vector<std::vector<std::pair<int, double>>> adj(nv);
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = m.F(f, k), j = m.F(f, (k + 1) % 3);
      const double len = (m.UV.row(m.FUV(f, k)) - m.UV.row(m.FUV(f, (k + 1) % 3))).norm();
      adj[i].push_back({j, len});
      adj[j].push_back({i, len});
    }
  // Multi-source Dijkstra from every pin; ties broken by vertex index (deterministic).
  std::vector<double> dist(nv, std::numeric_limits<double>::infinity());
  std::vector<int> source(nv, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (int p : pinned) {
    dist[p] = 0;
    source[p] = p;
    queue.push({0.0, p});
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    for (const auto& [u, len] : adj[v]) {
      const double nd = d + len;
      if (nd < dist[u] || (nd == dist[u] && source[v] < source[u])) {
        dist[u] = nd;
        source[u] = source[v];
        queue.push({nd, u});
      }
    }
  }
  // Straight lines in the flat pattern where both ends share a chart.
  const std::vector<int> chart = gdsr::uv_islands(m);
  std::vector<std::vector<int>> copies(nv);
  for (size_t u = 0; u < m.uv_to_vertex.size(); ++u) copies[m.uv_to_vertex[u]].push_back(static_cast<int>(u));
  std::vector<Tether> out;
  for (int v = 0; v < nv; ++v) {
    if (is_pin[v] || source[v] < 0) continue;
    double straight = std::numeric_limits<double>::infinity();
    for (int a : copies[v])
      for (int b : copies[source[v]])
        if (chart[a] == chart[b]) straight = std::min(straight, (m.UV.row(a) - m.UV.row(b)).norm());
    // A straight line much shorter than the edge path leaves the panel (round a cut-out); no
    // shared chart (the pin is on another panel): the edge path.
    const double rest = std::isfinite(straight) && straight >= dist[v] / 1.2 ? straight : dist[v];
    out.push_back({v, source[v], rest});
  }
  return out;
}

int project_tethers(const std::vector<Tether>& tethers, double max_stretch, gdsr::Points3& x) {
  int moved = 0;
  for (const Tether& t : tethers) {
    const gdsr::Vec3 d = x.row(t.v) - x.row(t.pin);
    const double len = d.norm(), limit = t.rest * (1 + max_stretch);
    if (len <= limit) continue;
    x.row(t.v) = x.row(t.pin) + (limit / len) * d.transpose();
    ++moved;
  }
  return moved;
}

}  // namespace sim

#include "gdsr/sim/cloth_pins.hpp"

#include "gdsr/error.hpp"
#include "gdsr/sim/cloth_collision.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <functional>
#include <map>
#include <queue>
#include <utility>

namespace sim {

using gdsr::Points3;
using gdsr::Vec3;

namespace {

// Body vertex adjacency with edge lengths on the pose V.
std::vector<std::vector<std::pair<int, double>>> body_graph(const gdsr::Faces& F, const Points3& V) {
  std::vector<std::vector<std::pair<int, double>>> adj(V.rows());
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = F(f, k), j = F(f, (k + 1) % 3);
      const double l = (V.row(i) - V.row(j)).norm();
      adj[i].push_back({j, l});
      adj[j].push_back({i, l});
    }
  for (auto& a : adj) {  // each undirected edge once per end, in a fixed order
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  return adj;
}

// Distances along body edges from the closest point (in face f) to every vertex within r.
std::map<int, double> geodesic_ball(const std::vector<std::vector<std::pair<int, double>>>& adj, const gdsr::Faces& F,
                                    const Points3& V, int f, const Vec3& point, double r) {
  std::map<int, double> dist;
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (int k = 0; k < 3; ++k) {
    const int v = F(f, k);
    // The triangle's own corners always carry the pin, however large the triangle.
    const double d = std::min((V.row(v).transpose() - point).norm(), 0.9 * r);
    if (!dist.count(v) || d < dist[v]) dist[v] = d;
    queue.push({d, v});
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    for (const auto& [u, l] : adj[v]) {
      const double du = d + l;
      if (du >= r) continue;
      auto it = dist.find(u);
      if (it == dist.end() || du < it->second) {
        dist[u] = du;
        queue.push({du, u});
      }
    }
  }
  return dist;
}

// Bands: connected components of the pinned vertices through the garment's edges; per pin,
// its band id (bands numbered in order of their smallest pin slot).
std::vector<int> pinned_bands(const std::vector<int>& pinned, const gdsr::Faces& F) {
  std::map<int, int> slot;
  for (size_t k = 0; k < pinned.size(); ++k) slot[pinned[k]] = static_cast<int>(k);
  std::vector<int> parent(pinned.size());
  for (size_t k = 0; k < parent.size(); ++k) parent[k] = static_cast<int>(k);
  std::function<int(int)> root = [&](int k) { return parent[k] == k ? k : parent[k] = root(parent[k]); };
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const auto i = slot.find(F(f, c)), j = slot.find(F(f, (c + 1) % 3));
      if (i == slot.end() || j == slot.end()) continue;
      const int a = root(i->second), b = root(j->second);
      parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<int> band(pinned.size());
  std::map<int, int> id;
  for (size_t k = 0; k < pinned.size(); ++k) band[k] = id.emplace(root(static_cast<int>(k)), id.size()).first->second;
  return band;
}

}  // namespace

PinBinding::PinBinding(const std::vector<int>& pinned, const Points3& placed, const gdsr::Faces& F,
                       const gdsr::Faces& body_F, const Points3& body_V0, double radius) {
  if (pinned.empty()) return;
  if (body_F.rows() == 0 || body_V0.rows() == 0) gdsr::fail("sim/cloth_pins", "pins need a body");
  if (static_cast<int>(placed.rows()) != static_cast<int>(pinned.size()))
    gdsr::fail("sim/cloth_pins", "placed positions and pinned vertices differ in count");
  if (!(radius > 0)) gdsr::fail("sim/cloth_pins", "radius must be positive");
  const auto adj = body_graph(body_F, body_V0);
  const std::vector<int> band_of = pinned_bands(pinned, F);
  const int nbands = 1 + *std::max_element(band_of.begin(), band_of.end());
  std::vector<std::map<int, double>> falloff(nbands);  // per band: body vertex -> largest falloff over its pins
  SurfaceGrid grid;
  double cell = 0;
  for (size_t k = 0; k < pinned.size(); ++k) {
    const Vec3 x = placed.row(k).transpose();
    SurfaceHit hit;
    for (double r = 0.1; hit.face < 0 && r < 5; r *= 2) {
      if (cell < r / 2) {
        cell = r / 2;
        grid.build(body_F, body_V0, body_V0, cell);
      }
      hit = grid.closest(x, body_V0, r);
    }
    if (hit.face < 0) gdsr::fail("sim/cloth_pins", "pinned vertex is more than 5 m from the body");
    for (const auto& [b, d] : geodesic_ball(adj, body_F, body_V0, hit.face, hit.point, radius)) {
      const double s = 1 - (d / radius) * (d / radius);
      double& w = falloff[band_of[k]][b];
      w = std::max(w, s * s);
    }
  }
  bands_.resize(nbands);
  for (int b = 0; b < nbands; ++b) {
    Band& band = bands_[b];
    double wsum = 0;
    for (const auto& [v, w] : falloff[b]) {
      band.body.push_back(v);
      band.weight.push_back(w);
      wsum += w;
    }
    band.centre0.setZero();
    for (size_t i = 0; i < band.body.size(); ++i) {
      band.weight[i] /= wsum;
      band.centre0 += band.weight[i] * body_V0.row(band.body[i]).transpose();
    }
    band.rel0.resize(static_cast<Eigen::Index>(band.body.size()), 3);
    for (size_t i = 0; i < band.body.size(); ++i)
      band.rel0.row(static_cast<Eigen::Index>(i)) = body_V0.row(band.body[i]) - band.centre0.transpose();
  }
  for (size_t k = 0; k < pinned.size(); ++k)
    pins_.push_back({pinned[k], band_of[k], Vec3(placed.row(k).transpose() - bands_[band_of[k]].centre0)});
}

void PinBinding::fit(int b, const Points3& body, Eigen::Matrix3d& R, Vec3& centre) const {
  const Band& band = bands_[b];
  centre.setZero();
  for (size_t i = 0; i < band.body.size(); ++i) centre += band.weight[i] * body.row(band.body[i]).transpose();
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // weighted cross-covariance, rest -> now
  for (size_t i = 0; i < band.body.size(); ++i)
    H += band.weight[i] * band.rel0.row(static_cast<Eigen::Index>(i)).transpose() *
         (body.row(band.body[i]).transpose() - centre).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) D(2, 2) = -1;  // a rotation, not a mirror
  R = svd.matrixV() * D * svd.matrixU().transpose();
}

void PinBinding::place(const Points3& body, Points3& x, std::vector<Eigen::Matrix3d>* rotations) const {
  std::vector<Eigen::Matrix3d> R(bands_.size());
  std::vector<Vec3> c(bands_.size());
  for (size_t b = 0; b < bands_.size(); ++b) fit(static_cast<int>(b), body, R[b], c[b]);
  for (const Pin& p : pins_) x.row(p.v) = (c[p.band] + R[p.band] * p.offset0).transpose();
  if (rotations) *rotations = std::move(R);
}

Vec3 PinBinding::position(int k, const Points3& body) const {
  Eigen::Matrix3d R;
  Vec3 c;
  fit(pins_[k].band, body, R, c);
  return c + R * pins_[k].offset0;
}

}  // namespace sim

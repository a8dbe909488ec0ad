#include "gdsr/sim/gauss_seidel_schedule.hpp"

#include "gdsr/error.hpp"

#include <algorithm>
#include <string>

namespace sim {

void GaussSeidelSchedule::plan(const std::vector<Item>& items, int num_vertices) {
  count_ = static_cast<int>(items.size());
  // Levels, and each item's last earlier item on each of its vertices (its predecessors).
  std::vector<int> last(num_vertices, -1), level(count_);
  std::vector<Item> pred(count_);
  levels_ = 0;
  for (int k = 0; k < count_; ++k) {
    int l = 0;
    for (int s = 0; s < 4; ++s) {
      const int v = items[k][s];
      pred[k][s] = -1;
      if (v < 0) continue;
      if (v >= num_vertices)
        gdsr::fail("sim/gauss_seidel_schedule", "item vertex " + std::to_string(v) + " out of range");
      pred[k][s] = last[v];
      if (last[v] >= 0) l = std::max(l, level[last[v]]);
    }
    level[k] = l + 1;
    levels_ = std::max(levels_, l + 1);
    for (int v : items[k])
      if (v >= 0) last[v] = k;
  }
  // Thread by the item's smallest vertex: below the split vertex list 0, else list 1, the split
  // chosen so that the lists are about equally long.
  auto key = [&](int k) {
    int m = num_vertices;
    for (int v : items[k])
      if (v >= 0) m = std::min(m, v);
    return m == num_vertices ? 0 : m;
  };
  std::vector<int> at_vertex(num_vertices + 1, 0);
  for (int k = 0; k < count_; ++k) ++at_vertex[key(k)];
  int split = 0;
  for (int below = 0; split < num_vertices && 2 * (below + at_vertex[split]) <= count_; ++split)
    below += at_vertex[split];
  // Each list in level order (counting sort; the sequential order within a level).
  std::vector<int> by_level(levels_ + 2, 0);
  for (int k = 0; k < count_; ++k) ++by_level[level[k] + 1];
  for (int l = 1; l < levels_ + 2; ++l) by_level[l] += by_level[l - 1];
  std::vector<int> order(count_);
  for (int k = 0; k < count_; ++k) order[by_level[level[k]]++] = k;
  std::vector<Step> lists[2];
  std::vector<int> list_of(count_), pos(count_);
  for (int k : order) {
    const int t = key(k) < split ? 0 : 1;
    list_of[k] = t;
    pos[k] = static_cast<int>(lists[t].size());
    lists[t].push_back({k, 0});
  }
  // Waits: a predecessor in the other list must be finished (a predecessor in the same list
  // comes earlier in it: its level is lower).
  for (int t = 0; t < 2; ++t)
    for (Step& s : lists[t])
      for (int q : pred[s.item])
        if (q >= 0 && list_of[q] != t) s.wait = std::max(s.wait, pos[q] + 1);
  first_[1] = static_cast<int>(lists[0].size());
  steps_ = std::move(lists[0]);
  steps_.insert(steps_.end(), lists[1].begin(), lists[1].end());
  slot_of_.resize(count_);
  for (int p = 0; p < count_; ++p) slot_of_[steps_[p].item] = p;
}

int GaussSeidelSchedule::waits(int t) const {
  const auto begin = steps_.begin() + (t ? first_[1] : 0), end = t ? steps_.end() : steps_.begin() + first_[1];
  return static_cast<int>(std::count_if(begin, end, [](const Step& s) { return s.wait > 0; }));
}

}  // namespace sim

// Disjoint sets over indices 0..n-1 as a parent array (parent[i] == i for a root).
#pragma once

#include <vector>

namespace gdsr {

// The root of i's set, halving the path on the way.
inline int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace gdsr

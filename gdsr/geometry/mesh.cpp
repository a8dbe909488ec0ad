#include "gdsr/geometry/mesh.hpp"

#include <algorithm>

namespace gdsr {

int GarmentMesh::num_layers() const {
  if (layer.empty()) return 1;
  return *std::max_element(layer.begin(), layer.end()) + 1;
}

}  // namespace gdsr

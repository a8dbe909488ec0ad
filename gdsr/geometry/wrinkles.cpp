#include "gdsr/geometry/wrinkles.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace gdsr {

WrinkleMeasure wrinkle_measure(const Points3& X, const Faces& F) {
  WrinkleMeasure w;
  std::map<std::pair<int, int>, std::vector<int>> ef;
  std::vector<Vec3> n(F.rows());
  double area = 0;
  for (int f = 0; f < F.rows(); ++f) {
    const Vec3 a = X.row(F(f, 0)), b = X.row(F(f, 1)), c = X.row(F(f, 2));
    const Vec3 cr = (b - a).cross(c - a);
    area += 0.5 * cr.norm();
    n[f] = cr.norm() > 0 ? Vec3(cr.normalized()) : Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      const int i = F(f, k), j = F(f, (k + 1) % 3);
      ef[{std::min(i, j), std::max(i, j)}].push_back(f);
    }
  }
  double sum_theta = 0, sum_tl = 0;
  int count = 0;
  for (const auto& [e, fs] : ef) {
    if (fs.size() != 2) continue;
    const double theta = std::atan2(n[fs[0]].cross(n[fs[1]]).norm(), n[fs[0]].dot(n[fs[1]]));
    sum_theta += theta;
    sum_tl += theta * (X.row(e.first) - X.row(e.second)).norm();
    ++count;
  }
  if (count > 0) w.mean_dihedral = sum_theta / count;
  if (area > 0) w.mean_curvature = sum_tl / (2 * area);
  return w;
}

}  // namespace gdsr

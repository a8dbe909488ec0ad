#include "gdsr/data/dataset_compare.hpp"

#include "gdsr/error.hpp"

#include <algorithm>
#include <cstring>
#include <numeric>

namespace gdsr {

double FrameDifference::clip_mean() const {
  return mean.empty() ? 0.0 : std::accumulate(mean.begin(), mean.end(), 0.0) / static_cast<double>(mean.size());
}

int FrameDifference::worst_frame() const {
  if (mean.empty()) return -1;
  return static_cast<int>(std::max_element(mean.begin(), mean.end()) - mean.begin());
}

FrameDifference frame_difference(const std::vector<Points3>& a, const std::vector<Points3>& b, const std::string& what) {
  if (a.size() != b.size())
    fail(what, std::to_string(a.size()) + " frames against " + std::to_string(b.size()));
  FrameDifference d;
  for (size_t t = 0; t < a.size(); ++t) {
    if (a[t].rows() != b[t].rows())
      fail(what, "frame " + std::to_string(t) + " has " + std::to_string(a[t].rows()) + " vertices against " +
                     std::to_string(b[t].rows()));
    double sum = 0;
    for (Eigen::Index v = 0; v < a[t].rows(); ++v) {
      const double dist = (a[t].row(v) - b[t].row(v)).norm();
      sum += dist;
      d.max = std::max(d.max, dist);
    }
    d.mean.push_back(a[t].rows() > 0 ? sum / static_cast<double>(a[t].rows()) : 0.0);
    if (a[t].size() > 0 && std::memcmp(a[t].data(), b[t].data(), sizeof(double) * a[t].size()) != 0) d.identical = false;
  }
  return d;
}

DatasetDifference compare_datasets(const Dataset& a, const Dataset& b) {
  return {frame_difference(a.lr_frames, b.lr_frames, "LR frames"), frame_difference(a.hr_frames, b.hr_frames, "HR frames")};
}

}  // namespace gdsr

#include "gdsr/io/point_cache.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"

#include <cstdint>
#include <cstring>

namespace gdsr {

namespace {

template <class T> void put(std::string& s, T x) {
  char b[sizeof(T)];
  std::memcpy(b, &x, sizeof(T));
  s.append(b, sizeof(T));
}

}  // namespace

void write_pc2(const std::string& path, const std::vector<Points3>& frames, float start_frame, float sample_rate) {
  if (frames.empty()) gdsr::fail(path, "no frames to write");
  if (!(sample_rate > 0)) gdsr::fail(path, "sample rate must be positive");
  const Eigen::Index n = frames[0].rows();
  for (size_t k = 0; k < frames.size(); ++k) {
    if (frames[k].rows() != n)
      gdsr::fail(path, "frame " + std::to_string(k) + " has " + std::to_string(frames[k].rows()) +
                           " vertices, frame 0 has " + std::to_string(n));
    if (!frames[k].allFinite()) gdsr::fail(path, "frame " + std::to_string(k) + " has a non-finite position");
  }
  std::string s;
  s.reserve(32 + frames.size() * static_cast<size_t>(n) * 12);
  s.append("POINTCACHE2", 12);  // 11 characters and the terminating zero
  put<int32_t>(s, 1);
  put<int32_t>(s, static_cast<int32_t>(n));
  put<float>(s, start_frame);
  put<float>(s, sample_rate);
  put<int32_t>(s, static_cast<int32_t>(frames.size()));
  for (const Points3& V : frames)
    for (Eigen::Index i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) put<float>(s, static_cast<float>(V(i, c)));
  write_file_atomic(path, s);
}

}  // namespace gdsr

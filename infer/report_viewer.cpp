#include "infer/report_viewer.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

namespace gdsr {

std::vector<std::string> write_viewer(const std::string& report_dir, const std::string& viewer_src) {
  namespace fs = std::filesystem;
  const std::string three = "node_modules/three/";
  // (source under viewer_src, destination under report_dir/viewer)
  const std::vector<std::pair<std::string, std::string>> files{
      {"index.html", "index.html"},
      {"viewer.js", "viewer.js"},
      {three + "build/three.module.js", "three/three.module.js"},
      {three + "examples/jsm/loaders/GLTFLoader.js", "three/addons/loaders/GLTFLoader.js"},
      {three + "examples/jsm/controls/OrbitControls.js", "three/addons/controls/OrbitControls.js"},
      {three + "examples/jsm/utils/BufferGeometryUtils.js", "three/addons/utils/BufferGeometryUtils.js"}};
  std::vector<std::string> contents;
  for (const auto& [src, dst] : files) {
    const fs::path p = fs::path(viewer_src) / src;
    std::ifstream in(p, std::ios::binary);
    if (!in)
      gdsr::fail(p.string(), src.rfind(three, 0) == 0 ? "missing: three.js is not installed (run scripts/setup.sh)"
                                                      : "missing: not the repository's viewer folder");
    std::stringstream ss;
    ss << in.rdbuf();
    contents.push_back(ss.str());
  }
  std::vector<std::string> written;
  for (size_t i = 0; i < files.size(); ++i) {
    const fs::path dst = fs::path(report_dir) / "viewer" / files[i].second;
    fs::create_directories(dst.parent_path());
    write_file_atomic(dst.string(), contents[i]);
    written.push_back("viewer/" + files[i].second);
  }
  return written;
}

}  // namespace gdsr

#include "gdsr/io/staged_folder.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/obj_io.hpp"

#include <filesystem>
#include <unistd.h>
#include <vector>

namespace gdsr {
namespace fs = std::filesystem;

StagedFolder::StagedFolder(const std::string& dir, const std::string& marker) : dir_(dir), marker_(marker) {
  if (dir.empty()) gdsr::fail("--out", "empty output folder name");
  fs::path d = fs::absolute(fs::path(dir)).lexically_normal();
  if (d.filename().empty()) d = d.parent_path();
  std::error_code ec;
  if (fs::exists(d, ec) && !fs::is_directory(d, ec)) gdsr::fail("--out", dir + " exists and is not a folder");
  fs::create_directories(d.parent_path(), ec);
  if (ec) gdsr::fail("--out", "cannot create " + d.parent_path().string() + ": " + ec.message());
  remove_stale_temps(d.parent_path().string(), {d.filename().string()});
  stage_ = d.string() + ".tmp." + std::to_string(static_cast<long>(::getpid()));
  fs::remove_all(stage_, ec);
  fs::create_directories(stage_, ec);
  if (ec) gdsr::fail("--out", "cannot create " + stage_ + ": " + ec.message());
}

StagedFolder::~StagedFolder() {
  std::error_code ec;
  fs::remove_all(stage_, ec);
}

void StagedFolder::commit() {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) gdsr::fail(dir_, "cannot create the folder: " + ec.message());
  const fs::path marker = fs::path(dir_) / marker_;
  if (!marker_.empty()) fs::remove(marker, ec);
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(stage_))
    if (!e.is_directory()) files.push_back(fs::relative(e.path(), stage_));
  for (const fs::path& rel : files) {
    if (rel == fs::path(marker_)) continue;
    const fs::path to = fs::path(dir_) / rel;
    fs::create_directories(to.parent_path(), ec);
    fs::rename(fs::path(stage_) / rel, to, ec);
    if (ec) gdsr::fail(to.string(), "cannot move the new file into place: " + ec.message());
  }
  if (!marker_.empty() && fs::exists(fs::path(stage_) / marker_)) {
    fs::rename(fs::path(stage_) / marker_, marker, ec);
    if (ec) gdsr::fail(marker.string(), "cannot move the new file into place: " + ec.message());
  }
}

}  // namespace gdsr

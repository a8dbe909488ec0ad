// Writing an output folder so that a failure (a full disk, a bad frame half-way) loses
// nothing: every file is written into a sibling stage folder "<dir>.tmp.<pid>", and only
// when all are written does commit() move them into `dir` one by one (renames need no new
// space), the marker file (e.g. prediction.json) removed first and moved in last, so a
// reader never sees the marker beside files of another run. Files of `dir` the run does not
// write stay. Destroyed without commit(), the stage is removed.
#pragma once

#include <string>

namespace gdsr {

class StagedFolder {
 public:
  StagedFolder(const std::string& dir, const std::string& marker);
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  const std::string& path() const { return stage_; }  // write the folder's files here
  void commit();

 private:
  std::string dir_, marker_, stage_;
};

}  // namespace gdsr

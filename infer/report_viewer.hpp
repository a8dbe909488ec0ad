// The browser viewer of a report (viewer/index.html + viewer/viewer.js of the repository):
// copied into REPORT/viewer/ with the three.js files it imports, so the report folder plays
// offline. three.js comes from viewer/node_modules/three (npm, fixed version in
// viewer/package.json, installed by scripts/setup.sh). The page reads REPORT/export/.
#pragma once

#include <string>
#include <vector>

namespace gdsr {

// viewer_src: the repository's viewer/ folder. Returns the paths written, relative to
// report_dir. Throws gdsr::Error naming the first missing source file (e.g. three.js not
// installed) before writing anything.
std::vector<std::string> write_viewer(const std::string& report_dir, const std::string& viewer_src);

}  // namespace gdsr

// Progress reporting from library code: a long computation calls progress(done, total) as it
// advances and never prints; the command line decides how to show it (gdsr/cli/progress_bar).
#pragma once

#include <functional>

namespace gdsr {

using ProgressFn = std::function<void(int done, int total)>;

}  // namespace gdsr

// The command line's progress bar (gdsr/cli/progress_bar.hpp) drawing on a non-terminal stream.
#include <doctest/doctest.h>

#include "gdsr/cli/progress_bar.hpp"

#include <sstream>
#include <string>

TEST_CASE("progress bar: draws in 10% steps off a terminal") {
  std::ostringstream os;
  {
    gdsr::ProgressBar bar("work", &os, 10);
    auto cb = bar.callback();
    for (int i = 1; i <= 50; ++i) cb(i, 50);
    bar.finish();
  }
  const std::string s = os.str();
  int lines = 0;
  for (char c : s) lines += c == '\n';
  CHECK(lines == 11);  // the first update (0%), then 10%, 20%, ..., 100%
  CHECK(s.find("work [##########] 100% 50/50") != std::string::npos);
  CHECK(s.find("work [#.........]  10% 5/50") != std::string::npos);
}

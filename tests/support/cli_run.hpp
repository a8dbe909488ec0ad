// Running the built gdsr executable from the CLI tests: exit status, stdout and stderr, and
// the check that a failure is one line "gdsr: error: ..." (header only, test code).
#pragma once

#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <cstdlib>
#include <string>
#include <sys/wait.h>

namespace gdsr_test {

struct Run {
  int status = -1;
  std::string out, err;
};

// `prefix` runs before the binary (e.g. a command that drops privileges).
inline Run gdsr_run(const TempDir& dir, const std::string& args, const std::string& prefix = "") {
  const std::string out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd =
      prefix + std::string("'") + GDSR_BINARY_DIR + "/gdsr' " + args + " >'" + out + "' 2>'" + err + "'";
  const int rc = std::system(cmd.c_str());
  Run r;
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

inline int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// Progress lines (stderr is not a terminal here) may precede the error; the error itself is
// the last line, exactly one line.
inline void check_one_line_error(const Run& r, const std::string& needle) {
  CHECK(r.status == 1);
  REQUIRE(!r.err.empty());
  CHECK(r.err.back() == '\n');
  const size_t start = r.err.rfind('\n', r.err.size() - 2);
  const std::string last = r.err.substr(start == std::string::npos ? 0 : start + 1);
  CHECK(last.rfind("gdsr: error: ", 0) == 0);
  CHECK(count_lines(r.err.substr(r.err.find("gdsr: error: "))) == 1);
  CHECK(last.find(needle) != std::string::npos);
  if (last.find(needle) == std::string::npos) MESSAGE("stderr: " << r.err);
}

}  // namespace gdsr_test

// Every input kept from fuzzing (tests/fuzz_corpus/<target>/, files that once crashed, hung
// or leaked an internal exception, and seeds) goes through the same reader entry point as
// the fuzzer's: it must load or be refused with a gdsr::Error / ag::Error, nothing else.
#include "fuzz/fuzz_targets.hpp"

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

TEST_CASE("fuzz: every kept input loads or gets a clean error") {
  const fs::path root = fs::path(GDSR_SOURCE_DIR) / "tests/fuzz_corpus";
  int files = 0;
  for (const gdsr_fuzz::Target& t : gdsr_fuzz::kTargets) {
    const fs::path dir = root / t.name;
    REQUIRE(fs::is_directory(dir));
    int here = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
      std::ifstream in(e.path(), std::ios::binary);
      std::stringstream ss;
      ss << in.rdbuf();
      INFO(e.path().string());
      CHECK_NOTHROW(gdsr_fuzz::run_one(t, ss.str()));
      ++here;
    }
    CHECK(here > 0);
    files += here;
  }
  MESSAGE(files << " kept inputs replayed");
}

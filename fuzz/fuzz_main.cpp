// One libFuzzer program per reader: GDSR_FUZZ_TARGET indexes gdsr_fuzz::kTargets.
#include "fuzz/fuzz_targets.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  gdsr_fuzz::run_one(gdsr_fuzz::kTargets[GDSR_FUZZ_TARGET], std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}

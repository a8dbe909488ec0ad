#include "autograd/runtime.hpp"

#include <climits>
#include <cstdlib>
#include <malloc.h>
#include <unistd.h>

namespace ag {

void configure_runtime(char** argv) {
  mallopt(M_MMAP_MAX, 0);              // large blocks from the heap, reused after free
  mallopt(M_TRIM_THRESHOLD, INT_MAX);  // and not given back to the system between frames
  if (std::getenv("OMP_WAIT_POLICY") || std::getenv("GOMP_SPINCOUNT")) return;
  if (!argv || !argv[0]) return;
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  execv("/proc/self/exe", argv);
  unsetenv("OMP_WAIT_POLICY");  // exec failed: carry on as before
}

const char* openmp_wait_policy() {
  const char* p = std::getenv("OMP_WAIT_POLICY");
  return p ? p : "default";
}

}  // namespace ag

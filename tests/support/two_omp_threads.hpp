// Two OpenMP threads for a test's scope: ctest runs with OMP_NUM_THREADS=1 (scripts/test.sh),
// which the solver's two-thread paths honour, so a test of those paths asks for two.
#pragma once

#include <omp.h>

namespace sim {

struct TwoOmpThreads {
  int before = omp_get_max_threads();
  TwoOmpThreads() { omp_set_num_threads(2); }
  ~TwoOmpThreads() { omp_set_num_threads(before); }
};

}  // namespace sim

// OpenMP threads for a test's scope: ctest runs with OMP_NUM_THREADS=1 (scripts/test.sh),
// which the solver's two-thread paths honour, so a test of those paths asks for two, and a
// test comparing them with the one-thread path asks for one (a local run may have more).
#pragma once

#include <omp.h>

namespace sim {

struct OmpThreads {
  int before = omp_get_max_threads();
  explicit OmpThreads(int n) { omp_set_num_threads(n); }
  ~OmpThreads() { omp_set_num_threads(before); }
  OmpThreads(const OmpThreads&) = delete;
  OmpThreads& operator=(const OmpThreads&) = delete;
};

struct TwoOmpThreads : OmpThreads {
  TwoOmpThreads() : OmpThreads(2) {}
};

}  // namespace sim

// Process-wide settings for the programs' main() (library code never calls these).
//
// Memory: a frame of the paper model allocates tensors of 40-160 MB each (the hyper-
// network's per-triangle fields). glibc serves blocks that large with a fresh mmap and
// returns them on free, so every frame pays page faults and kernel zeroing for ~1 GB
// (measured: more than half of an inference frame). Keeping freed memory in the heap
// makes later frames reuse it.
//
// Threads: GCC's OpenMP runtime (libgomp) lets idle threads spin before they sleep; when
// another process holds one of the cores, spinning and descheduled threads make parallel
// regions wait for time slices (measured: a small training step 10x slower). Passive
// waiting avoids that. libgomp reads its settings once, when the program is loaded, so
// they can only be changed by starting the program again.
#pragma once

namespace ag {

// First thing in main(): keeps large blocks in the heap (mallopt: no mmap, no trimming) and,
// if neither OMP_WAIT_POLICY nor GOMP_SPINCOUNT is set, sets OMP_WAIT_POLICY=passive and
// re-executes the program (/proc/self/exe, same arguments). Returns normally when nothing is
// to be done or re-executing is impossible (the program then runs with libgomp's defaults).
void configure_runtime(char** argv);

// The wait policy this process runs with: the value of OMP_WAIT_POLICY, or "default".
const char* openmp_wait_policy();

}  // namespace ag

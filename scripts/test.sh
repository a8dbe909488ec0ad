#!/usr/bin/env bash
# Builds (via setup.sh) and runs every test with ctest. Exit status is ctest's.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd build
# Count the cores without OMP_NUM_THREADS: GNU nproc honours it, and with it set to 1 (below)
# ctest ran every test one after another (CI took 1,030 s instead of about half that).
jobs="$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc 2>/dev/null || echo 2)"
# One OpenMP thread per test: ctest runs tests side by side, and oversubscribed OpenMP
# regions spin-wait (measured: a 4 s test took 255 s with 2 threads on a loaded machine). The
# library's two-thread regions honour it (tests/check_omp_threads.cmake checks every one).
export OMP_NUM_THREADS=1
ctest --output-on-failure -j"$jobs" --timeout 900 "$@"

#!/usr/bin/env bash
# Builds (via setup.sh) and runs every test with ctest. Exit status is ctest's.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd build
# One OpenMP thread per test: ctest runs tests side by side, and oversubscribed OpenMP
# regions spin-wait (measured: a 4 s test took 255 s with 2 threads on a loaded machine).
export OMP_NUM_THREADS=1
ctest --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" --timeout 900 "$@"

#!/usr/bin/env bash
# Installs the Debian packages gdsr needs (only the missing ones) and builds Release into
# ./build. Idempotent and quiet when everything is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(g++ cmake make libeigen3-dev libassimp-dev assimp-testmodels libembree-dev
          libopencv-dev doctest-dev libcli11-dev nlohmann-json3-dev libnanoflann-dev
          libcgal-dev libbenchmark-dev
          libopenmpi-dev openmpi-bin  # data-parallel training (cmake -DGDSR_MPI=ON; CI builds with it)
          blender python3-numpy  # the test that Blender opens the glTF / OBJ / PC2 exports
          chromium               # the test of the report's browser viewer (headless)
          strace)                # the tests that kill gdsr at each rename (fault injection)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
command -v npm >/dev/null || missing+=(npm)  # three.js for the viewer (any npm will do)
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# three.js for the report's browser viewer, at the exact version in viewer/package.json (it has
# no dependencies of its own, so no lock file).
if [ ! -f viewer/node_modules/three/build/three.module.js ]; then
  echo "setup: installing three.js into viewer/node_modules (npm)"
  (cd viewer && npm install --no-package-lock --no-audit --no-fund --loglevel=error >/dev/null)
fi

jobs=$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc 2>/dev/null || echo 2)  # nproc honours OMP_NUM_THREADS
# GDSR_CMAKE_ARGS: extra configure flags for a fresh build/ (CI passes -DGDSR_WERROR=ON;
# -DGDSR_MARCH=x86-64-v2 makes a build that runs on any x86-64 machine from 2009 on).
if [ ! -f build/CMakeCache.txt ]; then
  # shellcheck disable=SC2086
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release ${GDSR_CMAKE_ARGS:-} >/dev/null
  echo "setup: first build in build/ (about 10 minutes on 2 cores)"
fi
# Progress: the percentages make prints, on one line; the whole log is in build/build.log.
set +o pipefail
cmake --build build -j"$jobs" 2>&1 | tee build/build.log |
  grep --line-buffered -oE '^\[ *[0-9]+%\]' | uniq |
  awk '{ printf "%s ", $0; fflush() } END { if (NR) print "" }' >&2
status=${PIPESTATUS[0]}
set -o pipefail
if [ "$status" -ne 0 ]; then
  grep -E 'error|Error' build/build.log | head -30 >&2
  echo "setup: build failed (full log: build/build.log)" >&2
  exit 1
fi

#!/usr/bin/env bash
# Installs the Debian packages gdsr needs (only the missing ones) and builds Release into
# ./build. Idempotent and quiet when everything is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(g++ cmake make libeigen3-dev libassimp-dev assimp-testmodels libembree-dev
          libopencv-dev doctest-dev libcli11-dev nlohmann-json3-dev libnanoflann-dev
          libcgal-dev libbenchmark-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

jobs=$(nproc 2>/dev/null || echo 2)
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build build -j"$jobs" 2>&1 | grep -E 'error|warning: unused|Error' || true
cmake --build build -j"$jobs" >/dev/null   # fails loudly if the first pass failed

#!/usr/bin/env bash
# Builds (via setup.sh) and runs the main job on the built-in default data.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
./build/gdsr demo "$@"

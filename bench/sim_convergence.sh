#!/bin/sh
# Convergence study of the cloth solver (issue #10): one clip simulated with the LR particle
# distance at 30, 20 and 15 mm (each dataset pairs it with the same 10 mm HR simulation), then
# one table of their validity figures (scripts/validity_table.py). Its "HR-LR agreement"
# column is the mean distance between the HR frame and the upsampled LR frame: if the coarse
# shape converges, it falls as the LR distance approaches the HR one, and what remains at
# 30 mm is the discretisation error of the LR simulation, not a different drape.
#   bench/sim_convergence.sh BUILD_DIR OUT_DIR [GARMENT] [MOTION] [START_S] [SECONDS] ["LR_PDS"]
# Defaults: skirt_short on CMU 01_01 from 1 s for 1 s, LR_PDS "0.03 0.02 0.015". One thread
# each (OMP_NUM_THREADS=1), one after another: ~5 min per clip at 10 mm on this machine.
set -e
build=$(cd "${1:?usage: $0 BUILD_DIR OUT_DIR [GARMENT] [MOTION] [START_S] [SECONDS] [LR_PDS]}" && pwd)
out=${2:?usage: $0 BUILD_DIR OUT_DIR [GARMENT] [MOTION] [START_S] [SECONDS] [LR_PDS]}
garment=${3:-skirt_short}
motion=${4:-/usr/share/assimp/models/BVH/01_01.bvh}
start=${5:-1}
seconds=${6:-1}
pds=${7:-0.03 0.02 0.015}
mkdir -p "$out"
dirs=""
for pd in $pds; do
  d="$out/${garment}_lr$pd"
  echo "simulating $garment, LR $pd m / HR 0.01 m -> $d" >&2
  OMP_NUM_THREADS=1 "$build/gdsr" data make --garment "$garment" --motion "$motion" --start "$start" \
    --seconds "$seconds" --lr-pd "$pd" --hr-pd 0.01 --out "$d" > "$d.log" 2>&1 ||
    { echo "gdsr data make failed, see $d.log" >&2; exit 1; }
  dirs="$dirs $d"
done
python3 "$(dirname "$0")/../scripts/validity_table.py" $dirs

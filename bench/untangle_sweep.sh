#!/bin/sh
# Speed and validity of the untangling step (SimParams::untangle_step, issue #10): one clip
# simulated once per step (in self-thicknesses per substep; 0: off, revision 11), then one
# table of their validity figures next to the seconds per frame (scripts/validity_table.py).
# Untangling only acts on frames where an edge crosses a face, so the default clip is one that
# tangles: pants on CMU 131_01 from 2 s, where a lunge pinches the 10 mm trouser leg behind
# the knee at frame 44. Too large a step crumples the cloth instead (0.3: 16,407 pairs).
#   bench/untangle_sweep.sh BUILD_DIR OUT_DIR [GARMENT] [MOTION] [START_S] [SECONDS] ["STEPS"]
# Defaults: pants on ../shared/motions/cmu-walk/131_01.bvh from 2 s for 4 s, STEPS "0 0.05 0.1".
# One after another, one thread each (OMP_NUM_THREADS=1): ~8 min per run here.
set -e
usage="usage: $0 BUILD_DIR OUT_DIR [GARMENT] [MOTION] [START_S] [SECONDS] [STEPS]"
build=$(cd "${1:?$usage}" && pwd)
out=${2:?$usage}
garment=${3:-pants}
motion=${4:-$(dirname "$0")/../../shared/motions/cmu-walk/131_01.bvh}
start=${5:-2}
seconds=${6:-4}
steps=${7:-0 0.05 0.1}
[ -f "$motion" ] || { echo "$0: motion file $motion not found" >&2; exit 1; }
mkdir -p "$out"
dirs=""
for s in $steps; do
  d="$out/${garment}_untangle$s"
  echo "simulating $garment with --untangle-step $s -> $d" >&2
  OMP_NUM_THREADS=1 "$build/gdsr" data make --garment "$garment" --motion "$motion" --start "$start" \
    --seconds "$seconds" --untangle-step "$s" --out "$d" > "$d.log" 2>&1 ||
    { echo "gdsr data make failed, see $d.log" >&2; exit 1; }
  dirs="$dirs $d"
done
python3 "$(dirname "$0")/../scripts/validity_table.py" $dirs

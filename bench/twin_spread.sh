#!/bin/sh
# How far a clip's validity figures move under a change that should not matter (issue #10): the
# same clip made TWINS times with the friction nudged by k x 1e-5 (k = 0 .. TWINS-1 from the
# solver's 0.3, so the first twin is the default run), then one validity table of all of them
# (scripts/validity_table.py). A solver change whose figures stay inside this spread is not
# measured by one run of each: the 10 mm pants on CMU 131_02 (2-6 s) gave 44.1% and 100% of HR
# frames free of self-intersections for the first two twins of revision 12.
# FLAGS (one quoted argument) are passed to every `gdsr data make`, so that the spread of a
# candidate setting can be set beside the default's.
#   bench/twin_spread.sh BUILD_DIR OUT_DIR [GARMENT] [MOTION] [START_S] [SECONDS] [TWINS] ["FLAGS"]
# Defaults: pants on ../shared/motions/cmu-walk/131_02.bvh from 2 s for 4 s, 3 twins, no flags.
# One after another, one thread each (OMP_NUM_THREADS=1): ~8 min per twin here.
set -e
usage="usage: $0 BUILD_DIR OUT_DIR [GARMENT] [MOTION] [START_S] [SECONDS] [TWINS] [FLAGS]"
build=$(cd "${1:?$usage}" && pwd)
out=${2:?$usage}
garment=${3:-pants}
motion=${4:-$(dirname "$0")/../../shared/motions/cmu-walk/131_02.bvh}
start=${5:-2}
seconds=${6:-4}
twins=${7:-3}
flags=${8:-}
[ -f "$motion" ] || { echo "$0: motion file $motion not found" >&2; exit 1; }
case "$twins" in '' | *[!0-9]*) echo "$0: TWINS must be a positive integer, got '$twins'" >&2; exit 1 ;; esac
[ "$twins" -ge 1 ] || { echo "$0: TWINS must be at least 1" >&2; exit 1; }
mkdir -p "$out"
dirs=""
k=0
while [ "$k" -lt "$twins" ]; do
  friction=$(awk -v k="$k" 'BEGIN { printf "%.5f", 0.3 + k * 1e-5 }')
  d="$out/${garment}_friction$friction"
  echo "simulating $garment with --friction $friction $flags -> $d" >&2
  # shellcheck disable=SC2086  # FLAGS is a list of options
  OMP_NUM_THREADS=1 "$build/gdsr" data make --garment "$garment" --motion "$motion" --start "$start" \
    --seconds "$seconds" --friction "$friction" $flags --out "$d" > "$d.log" 2>&1 ||
    { echo "gdsr data make failed, see $d.log" >&2; exit 1; }
  dirs="$dirs $d"
  k=$((k + 1))
done
python3 "$(dirname "$0")/../scripts/validity_table.py" $dirs

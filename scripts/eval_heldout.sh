#!/bin/sh
# Roll-out evaluation of one model on held-out datasets (issue #12): `gdsr infer` then
# `gdsr eval` on each, then one table of GDSR against the upsampled LR input (vertex error,
# normal-map SSIM over the whole UV map and over the garment's pixels only, mean stretch/shear
# energies of the output), and the HR simulation at the LR scale (downsampled and upsampled:
# what a perfect correction E without detail would score).
#   scripts/eval_heldout.sh BUILD_DIR MODEL OUT_DIR DATASET...
# Example (the recipe's held-out clips):
#   scripts/eval_heldout.sh build models/gdsr_small_skirt.ckpt runs/eval \
#     runs/recipe/skirt_short_01_03_1s runs/recipe/skirt_short_60_03_2s
# GDSR_INFER_ARGS adds flags to gdsr infer, e.g. GDSR_INFER_ARGS="--ablate detail".
set -e
usage="usage: $0 BUILD_DIR MODEL OUT_DIR DATASET..."
build=$(cd "${1:?$usage}" && pwd)
model=${2:?$usage}
out=${3:?$usage}
shift 3
[ $# -gt 0 ] || { echo "$usage" >&2; exit 2; }
mkdir -p "$out"
reports=""
for data in "$@"; do
  name=$(basename "$data")
  echo "evaluating $model on $name" >&2
  # shellcheck disable=SC2086
  "$build/gdsr" infer --model "$model" --data "$data" --out "$out/$name" ${GDSR_INFER_ARGS:-} \
    > "$out/$name.infer.log" 2>&1 ||
    { echo "gdsr infer failed on $data, see $out/$name.infer.log" >&2; exit 1; }
  "$build/gdsr" eval --pred "$out/$name" --data "$data" --report "$out/$name.report" --no-video --no-export \
    > "$out/$name.eval.log" 2>&1 || { echo "gdsr eval failed on $data, see $out/$name.eval.log" >&2; exit 1; }
  reports="$reports $out/$name.report/report.json"
done
python3 - $reports <<'PY'
import json, sys
print("| dataset | frames | vertex error GDSR / upsampled (mm) | ratio | SSIM GDSR / upsampled | garment-pixel SSIM GDSR / upsampled | E_u | E_v | E_uv | s/frame | HR at the LR scale: mm, SSIM, garment-pixel SSIM |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for path in sys.argv[1:]:
    r = json.load(open(path))
    m = r["mean"]
    e = m["energies"]
    print("| %s | %d | %.2f / %.2f | %.2f | %.4f / %.4f | %.4f / %.4f | %.4f | %.4f | %.4f | %.3f | %.2f, %.4f, %.4f |" % (
        r["dataset"].rstrip("/").split("/")[-1], r["frames"], 1000 * m["error_m"], 1000 * m["error_lr_m"],
        m["error_m"] / m["error_lr_m"], m["ssim"], m["ssim_lr"], m["ssim_garment"], m["ssim_garment_lr"],
        e["E_u"], e["E_v"], e["E_uv"], r["seconds_per_frame"], 1000 * m["error_hr_lr_scale_m"],
        m["ssim_hr_lr_scale"], m["ssim_garment_hr_lr_scale"]))
PY

#!/bin/sh
# One table of the model's cost per preset (tiny, small, paper) on bench_model's garment:
# float32 inference s/frame, training step s/step (no VGG), float64 inference s/frame with
# the largest |G32 - G64| in mm, and the peak memory of each figure (each runs in its own
# process, so the peak is that figure's own: model, scene, activations and gradients).
#   bench/preset_table.sh BUILD_DIR [THREADS]
set -e
build=$(cd "${1:?usage: $0 BUILD_DIR [THREADS]}" && pwd)
threads=${2:-2}
cd "$build/bench"  # bench_model finds configs/ relative to its source path
# run FILTER -> "seconds peak_MiB max_diff_f32_mm" of the one benchmark FILTER selects
run() {
  OMP_NUM_THREADS=$threads ./bench_model --benchmark_filter="$1" --benchmark_format=csv 2>/dev/null | tr -d '"' |
    awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
             /^BM_/ { d = c["max_diff_f32_mm"] ? $(c["max_diff_f32_mm"]) : "-"
                      printf "%.4f %.0f %s\n", $(c["real_time"]) / 1000, $(c["peak_MiB"]), d }'
}
echo "threads=$threads omp_wait_policy=${OMP_WAIT_POLICY:-passive (bench_model's default)}"
echo "| preset | infer f32 s/frame | peak MiB | train s/step | peak MiB | infer f64 s/frame | peak MiB | max abs(G32-G64) mm |"
echo "|---|---|---|---|---|---|---|---|"
for p in tiny small paper; do
  set -- $(run "^BM_Inference/$p/") $(run "^BM_TrainStep/$p/") $(run "^BM_Inference64/$p/")
  echo "| $p | $1 | $2 | $4 | $5 | $7 | $8 | $9 |"
done

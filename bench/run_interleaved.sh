#!/bin/sh
# Our paper-preset inference next to the PyTorch yardstick (../shared/bench/), interleaved
# in one run (ours, torch, ours, torch, ...) because the machine is shared: compare the
# ratios, not the seconds. Also prints our dense-GEMM yardstick (GFLOP/s) each round.
#   bench/run_interleaved.sh BUILD_DIR [ROUNDS] [THREADS] [--train]
# With --train the training steps are compared instead (ours: BM_TrainStep/paper, without
# VGG and optimiser; the script's step includes VGG19 to relu5_1 and AdamW).
# Compare per block: our counters H_s, E_s, A_s, field_s with the script's H, E, A, field.
# The PyTorch side is bench-only and not part of scripts/setup.sh; install it with
#   apt-get install -y python3-torch python3-torchvision libopenblas0-pthread
# (without libopenblas0-pthread torch uses the reference BLAS, ~15x slower).
set -e
build=$(cd "${1:?usage: $0 BUILD_DIR [ROUNDS] [THREADS] [--train]}" && pwd)
rounds=${2:-2}
threads=${3:-2}
mode=${4:-}
here=$(cd "$(dirname "$0")" && pwd)
torch="$here/../../shared/bench/torch_gdsr_infer.py"
if [ "$mode" = "--train" ]; then filter='BM_TrainStep/paper|BM_DenseGemmReference'; else filter='BM_Inference/paper|BM_DenseGemmReference'; fi
i=1
while [ "$i" -le "$rounds" ]; do
  echo "== round $i: ours ($threads threads)"
  (cd "$build/bench" && OMP_NUM_THREADS=$threads ./bench_model --benchmark_filter="$filter" --benchmark_repetitions=2 \
    --benchmark_report_aggregates_only=false 2>/dev/null) | grep -E '^BM_' | grep -v -E '_(mean|median|stddev|cv) '
  echo "== round $i: torch ($threads threads)"
  if [ -f "$torch" ]; then /usr/bin/python3 "$torch" "$threads" $mode | grep -E 'seconds|train step'; else echo "(no $torch)"; fi
  i=$((i + 1))
done

#!/usr/bin/env bash
# The main job on the built-in default data, start to end (about 6 minutes on 2 cores):
#   1-2. `gdsr demo`: our autograd trains a small MLP; gradient-check summary of every op;
#   3.   paired LR (30 mm) / HR (10 mm) skirt simulations with our cloth solver on CMU
#        motion capture (HR follows LR at the LR scale and adds finer folds: --track-rate):
#        clip 01_01 for training, 01_03 (unseen motion) for testing;
#   4.   `gdsr train`: a small GDSR model on the training sequence;
#   5.   `gdsr infer` + `gdsr eval`: roll-out on the unseen motion, compared with the HR
#        simulation (vertex error, normal-map SSIM, stretch energies) and a preview PNG;
#        the report folder runs/demo/report (tables, plots, images, video, glTF / PC2 exports);
#   6.   the same with the trained model shipped in models/ (models/README.md: its data,
#        training and held-out figures, which this step reproduces), report runs/demo/report_shipped.
# Outputs go to runs/demo (override with GDSR_DEMO_OUT). Datasets already made from the same clip by
# the same solver revision are reused (data make --skip-built); others are rebuilt.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
gdsr=./build/gdsr
out=${GDSR_DEMO_OUT:-runs/demo}
bvh=/usr/share/assimp/models/BVH
mkdir -p "$out"

"$gdsr" demo

echo "== 3. Paired LR/HR data from our cloth simulator =="
"$gdsr" data make --skip-built --garment skirt_short --motion "$bvh/01_01.bvh" --start 1 --seconds 5 \
  --out "$out/train_skirt_01_01"
"$gdsr" data make --skip-built --garment skirt_short --motion "$bvh/01_03.bvh" --start 1 --seconds 2 \
  --out "$out/test_skirt_01_03"
"$gdsr" data preview --data "$out/train_skirt_01_01" --out "$out/data_preview.png"

echo "== 4. Train GDSR (configs/small.json) =="
"$gdsr" train --data "$out/train_skirt_01_01" --config configs/small.json --epochs 2 \
  --patches 2 --no-schedule --lr 3e-4 --log-every 50 --out "$out/model"

echo "== 5. Roll-out on the unseen motion 01_03, evaluation =="
"$gdsr" infer --model "$out/model/model.ckpt" --data "$out/test_skirt_01_03" --out "$out/infer"
"$gdsr" eval --pred "$out/infer" --data "$out/test_skirt_01_03" --report "$out/report"
echo "== 6. The shipped model (models/gdsr_small_skirt.ckpt, trained on three motions) on the same unseen motion =="
"$gdsr" infer --model models/gdsr_small_skirt.ckpt --data "$out/test_skirt_01_03" --out "$out/infer_shipped"
"$gdsr" eval --pred "$out/infer_shipped" --data "$out/test_skirt_01_03" --report "$out/report_shipped" \
  --no-video --no-export
echo "previews: $out/data_preview.png $out/infer/preview.png $out/infer_shipped/preview.png"
echo "report: $out/report/report.md (plots, LR | GDSR | HR images, rollout.avi, glTF / PC2 exports in export/)"

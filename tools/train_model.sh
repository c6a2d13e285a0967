#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Reproduces the shipped detector model (models/wingman-small.weights, card: models/wingman-small.md) on the CPU:
# imports the Halmstad videos (real, clip-split, tightened boxes, hard negatives), renders the synthetic set with the
# simulator, and trains models/wingman-small.cfg on both with the card's schedule. Resumable: run it again after an
# interruption and it continues from the last checkpoint (the datasets are kept once complete).
#
# Usage: tools/train_model.sh [--data DIR] [--out DIR] [--threads N] [--max-batches N]
#   --data         where the datasets go (default build/training-data; never inside the source tree's tracked files)
#   --out          training output: checkpoint.pt, progress.csv, *.weights (default build/train-wingman-small)
#   --threads      libtorch threads (default 2)
#   --max-batches  iterations (default 1500, the shipped run; the schedule scales with it)
# Needs ../shared/datasets/halmstad and a build with WINGMAN_WITH_TRAINING=ON and WINGMAN_WITH_SIM=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
bin="${WINGMAN_BIN_DIR:-$src/build/bin}"
data="$src/build/training-data" out="$src/build/train-wingman-small" threads=2 max_batches=1500
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --max-batches) max_batches="$2"; shift 2 ;;
    -h|--help) sed -n 3,13p "$0"; exit 0 ;;
    *) echo "train_model: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$max_batches" in ''|*[!0-9]*) echo "train_model: --max-batches '$max_batches': expected a positive integer" >&2; exit 2 ;; esac
halmstad_src="$src/../shared/datasets/halmstad"
[ -d "$halmstad_src" ] || { echo "train_model: $halmstad_src is missing (the Halmstad videos)" >&2; exit 2; }
"$bin/wingman" train --help > /dev/null 2>&1 ||
  { echo "train_model: $bin/wingman has no trainer: build with -DWINGMAN_WITH_TRAINING=ON (libtorch-dev)" >&2; exit 2; }
mkdir -p "$data" "$out"

# 1. Real data: every 10th frame of the drone clips, every 30th of the airplane/bird/helicopter clips (negatives).
if [ ! -f "$data/halmstad/data.yaml" ]; then
  rm -rf "$data/halmstad"
  "$bin/wingman" import-halmstad "$halmstad_src" "$data/halmstad"
fi
# 2. Synthetic data: 2000 domain-randomised images at 960x540 (the network sees 416x416 either way).
if [ ! -f "$data/synth/data.yaml" ]; then
  rm -rf "$data/synth"
  cat > "$data/synth.yaml" <<'EOF'
synth:
  width: 960
  height: 540
  image_format: "jpg"
  jpeg_quality: 92
render:
  supersampling: 1
EOF
  "$bin/wingman" dataset synth --out "$data/synth" --count 2000 --seed 7 --config "$data/synth.yaml" \
    --meshes "$src/../shared/meshes"
fi
cat > "$data/combined.yaml" <<EOF
# Training mix: Halmstad train clips plus simulator images; validation: the clip-disjoint Halmstad val clips.
path: $data
train: [halmstad/images/train, synth/images/train]
val: halmstad/images/val
nc: 1
names: [drone]
EOF

# 3. Train: Table 2's rate steps, scaled to the run's length; warm-up 100 iterations.
s1=$((max_batches * 53 / 100)) s2=$((max_batches * 77 / 100)) s3=$((max_batches * 90 / 100))
resume=()
[ -f "$out/checkpoint.pt" ] && resume=(--resume)
exec "$bin/wingman" train --cfg "$src/models/wingman-small.cfg" --data "$data/combined.yaml" --out "$out" \
  --threads "$threads" --max-batches "$max_batches" --burn-in 100 --learning-rate 0.002 \
  --steps "$s1,$s2,$s3" --scales 0.5,0.2,0.5 --scale 0.25 --translate 0.1 --blur 0.1 --noise 0.1 \
  --checkpoint-interval 25 --weights-interval 250 --log-interval 10 --val-max-images 400 "${resume[@]}"

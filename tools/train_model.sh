#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Reproduces the shipped detector model (models/wingman-small.weights, card: models/wingman-small.md) on the CPU:
# imports the Halmstad videos (real, clip-split, tightened boxes, hard negatives), renders the synthetic sets with
# the simulator, and trains models/wingman-small.cfg on Halmstad + synth with the card's schedule (stage 1), then
# fine-tunes stage 1's iteration-1000 weights for 400 iterations with the follower's-view set (drones on the
# horizon) added (stage 2). The shipped weights are stage 2's final ones (OUT/stage2/wingman-small_final.weights).
# Resumable: run it again after an interruption and it continues from the last checkpoint (datasets are kept once
# complete; a finished stage is not trained again).
#
# Usage: tools/train_model.sh [--data DIR] [--out DIR] [--threads N] [--max-batches N] [--stage2-batches N]
#   --data            where the datasets go (default build/training-data; never inside the source tree's tracked files)
#   --out             training output: checkpoint.pt, progress.csv, *.weights; stage 2's in OUT/stage2
#                     (default build/train-wingman-small)
#   --threads         libtorch threads (default 2)
#   --max-batches     stage 1 iterations (default 1500; the schedule scales with it)
#   --stage2-batches  stage 2 iterations (default 400, the shipped model's; 0 = stage 1 only). Stage 2 starts from
#                     stage 1's iteration-1000 weights (or its final ones when it is shorter)
# Needs ../shared/datasets/halmstad and a build with WINGMAN_WITH_TRAINING=ON and WINGMAN_WITH_SIM=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
bin="${WINGMAN_BIN_DIR:-$src/build/bin}"
data="$src/build/training-data" out="$src/build/train-wingman-small" threads=2 max_batches=1500 stage2_batches=400
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --max-batches) max_batches="$2"; shift 2 ;;
    --stage2-batches) stage2_batches="$2"; shift 2 ;;
    -h|--help) sed -n 3,18p "$0"; exit 0 ;;
    *) echo "train_model: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$max_batches" in ''|*[!0-9]*) echo "train_model: --max-batches '$max_batches': expected a positive integer" >&2; exit 2 ;; esac
case "$stage2_batches" in ''|*[!0-9]*) echo "train_model: --stage2-batches '$stage2_batches': expected an integer >= 0" >&2; exit 2 ;; esac
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

# 2b. The follower's view: 1500 images whose drone mostly flies at the camera's height, on the horizon, often against
# the treeline (the formation flights' view, which stage 1's data rarely shows).
if [ "$stage2_batches" -gt 0 ] && [ ! -f "$data/horizon/data.yaml" ]; then
  rm -rf "$data/horizon"
  cat > "$data/horizon.yaml" <<'EOF'
synth:
  width: 960
  height: 540
  hfov_min_deg: 60.0
  hfov_max_deg: 100.0
  range_min_m: 1.5
  range_max_m: 40.0
  camera_height_min_m: 2.0
  camera_height_max_m: 20.0
  camera_pitch_min_deg: -10.0
  camera_pitch_max_deg: 10.0
  camera_roll_max_deg: 5.0
  target_tilt_max_deg: 15.0
  horizon_fraction: 0.75
  horizon_elevation_max_deg: 3.0
  image_format: "jpg"
  jpeg_quality: 92
render:
  supersampling: 1
EOF
  "$bin/wingman" dataset synth --out "$data/horizon" --count 1500 --seed 11 --config "$data/horizon.yaml" \
    --meshes "$src/../shared/meshes"
fi
cat > "$data/combined-horizon.yaml" <<EOF
# Stage 2 mix: stage 1's plus the follower's-view set; validation: the clip-disjoint Halmstad val clips.
path: $data
train: [halmstad/images/train, synth/images/train, horizon/images/train]
val: halmstad/images/val
nc: 1
names: [drone]
EOF
common=(--cfg "$src/models/wingman-small.cfg" --threads "$threads" --scales 0.5,0.2,0.5 --scale 0.25 --translate 0.1
  --blur 0.1 --noise 0.1 --checkpoint-interval 25 --log-interval 10 --val-max-images 400)
# 3. Stage 1: Table 2's rate steps, scaled to the run's length; warm-up 100 iterations.
if [ ! -f "$out/wingman-small_final.weights" ]; then
  s1=$((max_batches * 53 / 100)) s2=$((max_batches * 77 / 100)) s3=$((max_batches * 90 / 100))
  resume=()
  [ -f "$out/checkpoint.pt" ] && resume=(--resume)
  "$bin/wingman" train "${common[@]}" --data "$data/combined.yaml" --out "$out" --max-batches "$max_batches" \
    --burn-in 100 --learning-rate 0.002 --steps "$s1,$s2,$s3" --weights-interval 250 "${resume[@]}"
fi
[ "$stage2_batches" -gt 0 ] || exit 0
# 4. Stage 2: fine-tune iteration 1000's weights at the rate stage 1 had there (1e-3), then Table 2's later steps.
init="$out/wingman-small_1000.weights"
[ -f "$init" ] || init="$out/wingman-small_final.weights"
t1=$((stage2_batches / 2)) t2=$((stage2_batches * 8 / 10)) t3=$((stage2_batches * 9 / 10))
resume=()
[ -f "$out/stage2/checkpoint.pt" ] && resume=(--resume)
exec "$bin/wingman" train "${common[@]}" --data "$data/combined-horizon.yaml" --out "$out/stage2" --weights "$init" \
  --max-batches "$stage2_batches" --burn-in 50 --learning-rate 0.001 --steps "$t1,$t2,$t3" --weights-interval 100 \
  "${resume[@]}"

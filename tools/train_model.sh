#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Reproduces the shipped detector model (models/wingman-small.weights, card: models/wingman-small.md) on the CPU:
# imports the Halmstad videos (real, clip-split, tightened boxes, hard negatives), renders the synthetic sets with
# the simulator, and trains models/wingman-small.cfg at 416x416 on Halmstad + synth with the card's schedule
# (stage 1), then fine-tunes stage 1's iteration-1000 weights for 400 iterations with the follower's-view set
# (drones on the horizon) added (stage 2), then flies eight training flights through the pipeline, takes their
# frames with the renderer's boxes, and fine-tunes stage 2 at the cfg's 640x352 with them added (stage 3), then grows
# the cfg's third head (stride 32, for large, close drones) on stage 3 with --partial-weights and trains the whole
# network on the same data (stage 4), then trains stage 4 longer with 2400 more synthetic 1280x720 images up to 30 m
# added (stage 5). Stages 1-3 train the cfg without its third head (the section from "# Third head" on cut, the
# first six anchors). Stage 5's final weights (OUT/stage5/wingman-small_final.weights) were shipped until
# 2026-12-04; the shipped weights now are stage 5 trained on by three runs of stage 6 (the card's "weight average",
# "stage 7" and "stage 8"; each run's averaged final weights start the next; about 2.8 h on 2 cores):
#   tools/train_model.sh --out build/train-avg --stage6-batches 800 \
#     --stage6-init build/train-wingman-small/stage5/wingman-small_final.weights \
#     --stage6-iou-loss ciou --stage6-iou-normalizer 1.5 --stage6-mix s5 --stage6-ema 0.99
#   tools/train_model.sh --out build/train-s7 --stage6-batches 1200 \
#     --stage6-init build/train-avg/stage6-ciou-1.5-s5mix-ema0.99/wingman-small_final.weights \
#     --stage6-iou-loss ciou --stage6-iou-normalizer 1.5 --stage6-mix s5 --stage6-ema 0.99
#   tools/train_model.sh --out build/train-s8 --stage6-batches 800 \
#     --stage6-init build/train-s7/stage6-ciou-1.5-s5mix-ema0.99/wingman-small_final.weights \
#     --stage6-iou-loss ciou --stage6-iou-normalizer 3 --stage6-mix s5 --stage6-ema 0.99
# and the shipped file is the last run's trained (not averaged) weights,
# build/train-s8/stage6-ciou-3-s5mix-ema0.99/wingman-small_raw_final.weights.
# Resumable: run it again after an interruption and it continues from the last checkpoint (datasets are kept once
# complete; a finished stage is not trained again).
# The stages, datasets, mixes and .cfg variants are config/training/wingman-small.yaml (the distractor-class run:
# config/training/wingman-small-distractors.yaml), run by `wingman train-recipe`; this script turns its options into
# the recipe's keys (--set) and prints every command before it runs (--dry-run: only prints them).
#
# Usage: tools/train_model.sh [--data DIR] [--out DIR] [--threads N] [--max-batches N] [--stage2-batches N]
#                             [--stage3-batches N] [--stage4-batches N]
#                             [--stage5-batches N] [--stage6-batches N] [--stage6-init FILE]
#                             [--stage6-iou-loss KIND] [--stage6-iou-normalizer X] [--stage6-mix s5|s6]
#                             [--stage6-ema DECAY]
#                             [--distractors-batches N] [--distractors-init CFG WEIGHTS]
#                             [--data-only] [--dry-run]
#   --data            where the datasets go (default build/training-data; never inside the source tree's tracked files)
#   --out             training output: checkpoint.pt, progress.csv, *.weights; stages 2 to 5 in OUT/stage2 .. OUT/stage5
#                     (default build/train-wingman-small)
#   --threads         libtorch threads (default 2)
#   --max-batches     stage 1 iterations (default 1500; the schedule scales with it)
#   --stage2-batches  stage 2 iterations (default 400, the shipped model's; 0 = stage 1 only). Stage 2 starts from
#                     stage 1's iteration-1000 weights (or its final ones when it is shorter)
#   --stage3-batches  stage 3 iterations (default 400, the shipped model's; 0 = stop after stage 2)
#   --stage4-batches  stage 4 iterations (default 600; 0 = stop after stage 3)
#   --stage5-batches  stage 5 iterations (default 1000, the shipped model's; 0 = stop after stage 4)
#   --stage6-batches  stage 6 iterations (default 0: stop after stage 5). Stage 6 trains stage 5's
#                     final weights longer with a second set of 2400 synthetic 1280x720 images (seed 41) added
#   --stage6-init     FILE: stage 6 starts from FILE (e.g. stage 5's final weights, or a stage-6 run's) and stages 1-5
#                     are not trained (their datasets are still prepared: stage 6 trains on them)
#   --stage6-iou-loss KIND: stage 6's [yolo] box loss, mse (default, the cfg's), giou, diou or ciou: stage 6 then
#                     trains a copy of the cfg with iou_loss=KIND in every [yolo] section (OUT/cfg-KIND), into
#                     OUT/stage6-KIND (OUT/stage6-KIND-X with a normalizer X other than 0.75)
#   --stage6-iou-normalizer X: that copy's iou_normalizer (default 0.75, the trainer's)
#   --stage6-mix      s6 (default): stage 6 trains on stage 5's mix plus the second synthetic 1280x720 set; s5:
#                     on stage 5's mix alone (the second set is not rendered), into OUT/stage6[-KIND[-X]]-s5mix
#   --stage6-ema      DECAY: stage 6 keeps an exponential moving average of its weights (`wingman train --ema-decay`)
#                     and exports it; its trained weights stay beside it as wingman-small_raw_*.weights. Into
#                     OUT/stage6[-KIND[-X]][-s5mix]-emaDECAY (default: no average)
#   --distractors-batches N: the distractor-class run (default 0: none), instead of stages 1-6: the model of
#                     --distractors-init (default the shipped one) widened to 4 classes (drone, airplane, bird,
#                     helicopter; `wingman model widen-classes`, with stage 8's box loss: ciou at 3) and trained N
#                     iterations on the Halmstad clips imported with their airplane/bird/helicopter boxes as classes
#                     (`wingman import-halmstad --distractor-classes`, every 10th frame of every clip, into
#                     DATA/halmstad-classes), stage 1's synthetic set, the follower's-view set and the synthetic
#                     1280x720 training set, at 5e-4 (then x0.5, x0.2, x0.5 at N/2, 8N/10, 9N/10; burn-in 30), with
#                     the weight average (EMA 0.99) exported. Into OUT/distractors; resumable like the others
#   --distractors-init CFG WEIGHTS: the model the distractor-class run starts from (default
#                     models/wingman-small.cfg and models/wingman-small.weights)
#   --data-only       prepare every dataset the stages use (import, render, fly) and train nothing
#   --dry-run         print the commands it would run (`wingman train-recipe --dry-run`) and run nothing
# Needs ../shared/datasets/halmstad and a build with WINGMAN_WITH_TRAINING=ON and WINGMAN_WITH_SIM=ON; the training
# flights need what tools/fly.sh needs (a private network namespace) and 3.3 GB of disk for one log at a time.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
bin="${WINGMAN_BIN_DIR:-$src/build/bin}"
data="$src/build/training-data" out="$src/build/train-wingman-small" threads=2 max_batches=1500 stage2_batches=400
stage3_batches=400 stage4_batches=600 stage5_batches=1000 stage6_batches=0 stage6_init="" data_only=0 dry_run=0
stage6_iou_loss=mse stage6_iou_normalizer=0.75 stage6_mix=s6 stage6_ema=""
distractors_batches=0 distractors_cfg="$src/models/wingman-small.cfg" distractors_weights="$src/models/wingman-small.weights"
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --max-batches) max_batches="$2"; shift 2 ;;
    --stage2-batches) stage2_batches="$2"; shift 2 ;;
    --stage3-batches) stage3_batches="$2"; shift 2 ;;
    --stage4-batches) stage4_batches="$2"; shift 2 ;;
    --stage5-batches) stage5_batches="$2"; shift 2 ;;
    --stage6-batches) stage6_batches="$2"; shift 2 ;;
    --stage6-init) stage6_init="$2"; shift 2 ;;
    --stage6-iou-loss) stage6_iou_loss="$2"; shift 2 ;;
    --stage6-iou-normalizer) stage6_iou_normalizer="$2"; shift 2 ;;
    --stage6-mix) stage6_mix="$2"; shift 2 ;;
    --stage6-ema) stage6_ema="$2"; shift 2 ;;
    --distractors-batches) distractors_batches="$2"; shift 2 ;;
    --distractors-init) distractors_cfg="$2"; distractors_weights="$3"; shift 3 ;;
    --data-only) data_only=1; shift ;;
    --dry-run) dry_run=1; shift ;;
    -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "train_model: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$max_batches" in ''|*[!0-9]*) echo "train_model: --max-batches '$max_batches': expected a positive integer" >&2; exit 2 ;; esac
for pair in "stage2 $stage2_batches" "stage3 $stage3_batches" "stage4 $stage4_batches" "stage5 $stage5_batches" \
            "stage6 $stage6_batches" "distractors $distractors_batches"; do
  read -r stage n <<<"$pair"
  case "$n" in ''|*[!0-9]*) echo "train_model: --$stage-batches '$n': expected an integer >= 0" >&2; exit 2 ;; esac
  # Stages 2-6 step their rate at N/2, 8N/10 and 9N/10 iterations: those must increase, so N is 0 or at least 6.
  if [ "$n" -gt 0 ] && [ "$n" -lt 6 ]; then
    echo "train_model: --$stage-batches $n: expected 0 (skip the stage) or at least 6 (its rate steps at N/2, 8N/10 and 9N/10 must increase)" >&2
    exit 2
  fi
done
[ "$max_batches" -ge 5 ] || { echo "train_model: --max-batches $max_batches: expected at least 5 (its rate steps at 53, 77 and 90 % must increase)" >&2; exit 2; }
case "$stage6_iou_loss" in mse|giou|diou|ciou) ;; *) echo "train_model: --stage6-iou-loss '$stage6_iou_loss': expected mse, giou, diou or ciou" >&2; exit 2 ;; esac
case "$stage6_mix" in s5|s6) ;; *) echo "train_model: --stage6-mix '$stage6_mix': expected s5 or s6" >&2; exit 2 ;; esac
[ -z "$stage6_ema" ] || [[ "$stage6_ema" =~ ^0\.[0-9]*[1-9][0-9]*$ ]] ||
  { echo "train_model: --stage6-ema '$stage6_ema': expected a decay in (0, 1), e.g. 0.99" >&2; exit 2; }
case "$stage6_iou_normalizer" in ''|*[!0-9.]*|*.*.*|.) echo "train_model: --stage6-iou-normalizer '$stage6_iou_normalizer': expected a positive number" >&2; exit 2 ;; esac
if [ -n "$stage6_init" ]; then
  [ -f "$stage6_init" ] || { echo "train_model: --stage6-init '$stage6_init': no such file" >&2; exit 2; }
  [ "$stage6_batches" -gt 0 ] || { echo "train_model: --stage6-init needs --stage6-batches > 0" >&2; exit 2; }
  stage6_init=$(cd "$(dirname "$stage6_init")" && pwd)/$(basename "$stage6_init")
fi
for f in "$distractors_cfg" "$distractors_weights"; do
  [ -f "$f" ] || { echo "train_model: --distractors-init: '$f': no such file" >&2; exit 2; }
done
distractors_cfg=$(cd "$(dirname "$distractors_cfg")" && pwd)/$(basename "$distractors_cfg")
distractors_weights=$(cd "$(dirname "$distractors_weights")" && pwd)/$(basename "$distractors_weights")

run=(--src "$src" --bin "$bin" --data "$data" --out "$out")
[ "$data_only" = 0 ] || run+=(--data-only)
[ "$dry_run" = 0 ] || run+=(--dry-run)
if [ "$distractors_batches" -gt 0 ]; then
  # The distractor-class run, instead of stages 1-6.
  exec "$bin/wingman" train-recipe "$src/config/training/wingman-small-distractors.yaml" "${run[@]}" \
    --set "train.threads=$threads" --set "distractors.batches=$distractors_batches" \
    --set "distractors.widen.cfg=$distractors_cfg" --set "distractors.widen.weights=$distractors_weights"
fi
# Stage 6's variant: the box loss (a copy of the cfg with it in every [yolo], OUT/cfg-KIND[-X]), the mix and the
# weight average name its folder OUT/stage6[-KIND[-X]][-s5mix][-emaDECAY].
out6=stage6
if [ "$stage6_iou_loss" != mse ]; then
  out6="stage6-$stage6_iou_loss"
  [ "$stage6_iou_normalizer" = 0.75 ] || out6="$out6-$stage6_iou_normalizer"
fi
[ "$stage6_mix" = s5 ] && out6="$out6-s5mix"
[ -z "$stage6_ema" ] || out6="$out6-ema$stage6_ema"
run+=(--set "train.threads=$threads" --set "stage1.batches=$max_batches" --set "stage2.batches=$stage2_batches"
  --set "stage3.batches=$stage3_batches" --set "stage4.batches=$stage4_batches" --set "stage5.batches=$stage5_batches"
  --set "stage6.batches=$stage6_batches" --set "stage6.mix=combined-$stage6_mix" --set "stage6.out=$out6"
  --set "stage6.iou_loss=$stage6_iou_loss" --set "stage6.iou_normalizer=$stage6_iou_normalizer")
[ -z "$stage6_ema" ] || run+=(--set "stage6.ema_decay=$stage6_ema")
# --stage6-init: stages 1-5 are not trained (their datasets are still prepared: stage 6 trains on them).
[ -z "$stage6_init" ] || run+=(--stage stage6 --init "$stage6_init")
exec "$bin/wingman" train-recipe "$src/config/training/wingman-small.yaml" "${run[@]}"

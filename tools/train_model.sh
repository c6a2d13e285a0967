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
#
# Usage: tools/train_model.sh [--data DIR] [--out DIR] [--threads N] [--max-batches N] [--stage2-batches N]
#                             [--stage3-batches N] [--stage4-batches N]
#                             [--stage5-batches N] [--stage6-batches N] [--stage6-init FILE]
#                             [--stage6-iou-loss KIND] [--stage6-iou-normalizer X] [--stage6-mix s5|s6]
#                             [--stage6-ema DECAY]
#                             [--distractors-batches N] [--distractors-init CFG WEIGHTS]
#                             [--data-only]
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
# Needs ../shared/datasets/halmstad and a build with WINGMAN_WITH_TRAINING=ON and WINGMAN_WITH_SIM=ON; the training
# flights need what tools/fly.sh needs (a private network namespace) and 3.3 GB of disk for one log at a time.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
bin="${WINGMAN_BIN_DIR:-$src/build/bin}"
data="$src/build/training-data" out="$src/build/train-wingman-small" threads=2 max_batches=1500 stage2_batches=400
stage3_batches=400 stage4_batches=600 stage5_batches=1000 stage6_batches=0 stage6_init="" data_only=0
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
    -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "train_model: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$max_batches" in ''|*[!0-9]*) echo "train_model: --max-batches '$max_batches': expected a positive integer" >&2; exit 2 ;; esac
case "$stage2_batches" in ''|*[!0-9]*) echo "train_model: --stage2-batches '$stage2_batches': expected an integer >= 0" >&2; exit 2 ;; esac
case "$stage3_batches" in ''|*[!0-9]*) echo "train_model: --stage3-batches '$stage3_batches': expected an integer >= 0" >&2; exit 2 ;; esac
case "$stage4_batches" in ''|*[!0-9]*) echo "train_model: --stage4-batches '$stage4_batches': expected an integer >= 0" >&2; exit 2 ;; esac
case "$stage5_batches" in ''|*[!0-9]*) echo "train_model: --stage5-batches '$stage5_batches': expected an integer >= 0" >&2; exit 2 ;; esac
case "$stage6_batches" in ''|*[!0-9]*) echo "train_model: --stage6-batches '$stage6_batches': expected an integer >= 0" >&2; exit 2 ;; esac
# Stages 2-6 step their rate at N/2, 8N/10 and 9N/10 iterations: those must increase, so N is 0 or at least 6.
for pair in "stage2 $stage2_batches" "stage3 $stage3_batches" "stage4 $stage4_batches" "stage5 $stage5_batches" \
            "stage6 $stage6_batches"; do
  read -r stage n <<<"$pair"
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
case "$distractors_batches" in ''|*[!0-9]*) echo "train_model: --distractors-batches '$distractors_batches': expected an integer >= 0" >&2; exit 2 ;; esac
if [ "$distractors_batches" -gt 0 ] && [ "$distractors_batches" -lt 6 ]; then
  echo "train_model: --distractors-batches $distractors_batches: expected 0 or at least 6 (its rate steps at N/2, 8N/10 and 9N/10 must increase)" >&2
  exit 2
fi
for f in "$distractors_cfg" "$distractors_weights"; do
  [ -f "$f" ] || { echo "train_model: --distractors-init: '$f': no such file" >&2; exit 2; }
done
distractors_cfg=$(cd "$(dirname "$distractors_cfg")" && pwd)/$(basename "$distractors_cfg")
distractors_weights=$(cd "$(dirname "$distractors_weights")" && pwd)/$(basename "$distractors_weights")
# Stages 1-5 train unless only the data is wanted, stage 6 starts from a given file, or the distractor-class run runs.
train_early=1
{ [ "$data_only" = 1 ] || [ -n "$stage6_init" ] || [ "$distractors_batches" -gt 0 ]; } && train_early=0
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
# Stages 1 and 2 train the network at 416x416 (the .cfg with that input size); stage 3 at the .cfg's own 640x352.
# The copy keeps the name wingman-small.cfg (the trainer names its files after the cfg: wingman-small_*.weights) in
# a folder of its own (the trainer copies its cfg into OUT).
# Stages 1-3: the two-head network (the shipped cfg without its third head, and with the first six anchors, so that
# every box trains one of the two heads). Each copy keeps the name wingman-small.cfg in a folder of its own.
mkdir -p "$out/cfg-416" "$out/cfg-2head"
# shellcheck disable=SC2016  # sed's $ (the last line), not a shell expansion
two_head=(-e '/^# Third head/,$d' -e 's/^anchors=.*/anchors=4,3, 6,5, 9,8, 13,13, 21,16, 34,27/' -e 's/^num=9$/num=6/')
sed "${two_head[@]}" "$src/models/wingman-small.cfg" > "$out/cfg-2head/wingman-small.cfg"
sed 's/^width=.*/width=416/; s/^height=.*/height=416/' "$out/cfg-2head/wingman-small.cfg" > "$out/cfg-416/wingman-small.cfg"
# shellcheck disable=SC2054  # --scales takes one comma-separated value
augment=(--threads "$threads" --scales 0.5,0.2,0.5 --scale 0.25 --translate 0.1 --blur 0.1 --noise 0.1
  --checkpoint-interval 25 --log-interval 10 --val-max-images 400)
common=(--cfg "$out/cfg-416/wingman-small.cfg" "${augment[@]}")
common640=(--cfg "$out/cfg-2head/wingman-small.cfg" "${augment[@]}")
# The synthetic 1280x720 training set (stage 5 on, and the distractor-class run).
render_synth720train() {
  if [ ! -f "$data/synth720train/data.yaml" ]; then
    rm -rf "$data/synth720train"
    sed 's/^  val_fraction: .*/  val_fraction: 0.0/' "$src/config/datasets/synth720.yaml" > "$data/synth720train.yaml"
    grep -q '^  val_fraction: 0.0$' "$data/synth720train.yaml" ||
      { echo "train_model: config/datasets/synth720.yaml has no synth.val_fraction line to set to 0" >&2; exit 1; }
    "$bin/wingman" dataset synth --out "$data/synth720train" --count 2400 --seed 23 --config "$data/synth720train.yaml" \
      --meshes "$src/../shared/meshes"
  fi
}

# The distractor-class run (--distractors-batches): the starting model widened to 4 classes, trained on the Halmstad
# clips with their distractor boxes as classes beside the synthetic sets; then exit.
if [ "$distractors_batches" -gt 0 ]; then
  if [ ! -f "$data/halmstad-classes/data.yaml" ]; then
    rm -rf "$data/halmstad-classes"
    "$bin/wingman" import-halmstad "$halmstad_src" "$data/halmstad-classes" --distractor-classes --negative-frame-step 10
  fi
  render_synth720train
  cat > "$data/combined-distractors.yaml" <<EOF
# The distractor-class run's mix: the Halmstad train clips with airplane, bird and helicopter boxes as classes 1-3,
# and the synthetic sets of stages 1, 2 and 5 (drones only); validation: the clip-disjoint Halmstad val clips.
path: $data
train: [halmstad-classes/images/train, synth/images/train, horizon/images/train, synth720train/images/train]
val: halmstad-classes/images/val
nc: 4
names: [drone, airplane, bird, helicopter]
EOF
  outd="$out/distractors"
  if [ ! -f "$outd/init/wingman-small.weights" ]; then
    "$bin/wingman" model widen-classes --cfg "$distractors_cfg" --weights "$distractors_weights" --classes 4 \
      --iou-loss ciou --iou-normalizer 3 --out-cfg "$outd/init/wingman-small.cfg" \
      --out-weights "$outd/init/wingman-small.weights"
  fi
  [ -f "$outd/wingman-small_final.weights" ] && exit 0
  u1=$((distractors_batches / 2)) u2=$((distractors_batches * 8 / 10)) u3=$((distractors_batches * 9 / 10))
  resume=()
  [ -f "$outd/checkpoint.pt" ] && resume=(--resume)
  exec "$bin/wingman" train --cfg "$outd/init/wingman-small.cfg" "${augment[@]}" \
    --data "$data/combined-distractors.yaml" --out "$outd" --weights "$outd/init/wingman-small.weights" \
    --max-batches "$distractors_batches" --burn-in 30 --learning-rate 0.0005 --steps "$u1,$u2,$u3" \
    --weights-interval 100 --ema-decay 0.99 "${resume[@]}"
fi

# 3. Stage 1: Table 2's rate steps, scaled to the run's length; warm-up 100 iterations.
if [ "$train_early" = 1 ] && [ ! -f "$out/wingman-small_final.weights" ]; then
  s1=$((max_batches * 53 / 100)) s2=$((max_batches * 77 / 100)) s3=$((max_batches * 90 / 100))
  resume=()
  [ -f "$out/checkpoint.pt" ] && resume=(--resume)
  "$bin/wingman" train "${common[@]}" --data "$data/combined.yaml" --out "$out" --max-batches "$max_batches" \
    --burn-in 100 --learning-rate 0.002 --steps "$s1,$s2,$s3" --weights-interval 250 "${resume[@]}"
fi
[ "$stage2_batches" -gt 0 ] || exit 0
# 4. Stage 2: fine-tune iteration 1000's weights at the rate stage 1 had there (1e-3), then Table 2's later steps.
if [ "$train_early" = 1 ] && [ ! -f "$out/stage2/wingman-small_final.weights" ]; then
  init="$out/wingman-small_1000.weights"
  [ -f "$init" ] || init="$out/wingman-small_final.weights"
  t1=$((stage2_batches / 2)) t2=$((stage2_batches * 8 / 10)) t3=$((stage2_batches * 9 / 10))
  resume=()
  [ -f "$out/stage2/checkpoint.pt" ] && resume=(--resume)
  "$bin/wingman" train "${common[@]}" --data "$data/combined-horizon.yaml" --out "$out/stage2" --weights "$init" \
    --max-batches "$stage2_batches" --burn-in 50 --learning-rate 0.001 --steps "$t1,$t2,$t3" --weights-interval 100 \
    "${resume[@]}"
fi
[ "$stage3_batches" -gt 0 ] || exit 0

# 5. Stage 3 data: the flights' own view. Eight training flights (tools/make_training_flights.py, seed 1: a hovering
# camera, the leader on random waypoints 3-30 m ahead, 40 s each; not the evaluation scenarios) flown through the
# real pipeline with ground-truth detections, every frame recorded; every 5th frame kept with the renderer's
# silhouette boxes (`wingman dataset from-log`); flights 0-6 train, flight 7 val. The 3 GB logs are deleted after;
# an interrupted run keeps the flights it finished.
if [ ! -f "$data/flights/.complete" ]; then
  python3 "$src/tools/make_training_flights.py" --out "$data/flight-logs/scenarios" --count 8 --seed 1 --duration 40
  for k in 0 1 2 3 4 5 6 7; do
    name=$(printf 'train_flight_%02d' "$k")
    [ -f "$data/flight-logs/$name.done" ] && continue  # kept from an interrupted run
    rm -rf "$data/flight-logs/$name"
    rm -f "$data"/flights/images/*/"$name"_* "$data"/flights/labels/*/"$name"_*
    WINGMAN_BIN_DIR="$bin" "$src/tools/fly.sh" --scenario "$data/flight-logs/scenarios/$name.yaml" \
      --out "$data/flight-logs/$name" --detections truth --truth-box silhouette --render --record-images \
      > "$data/flight-logs/$name.log" 2>&1 ||
      { echo "train_model: the training flight $name failed (log: $data/flight-logs/$name.log)" >&2; exit 1; }
    mv "$data/flight-logs/$name/flight.lcmlog" "$data/flight-logs/$name/$name.lcmlog"
    split="train"
    [ "$k" = 7 ] && split="val"
    "$bin/wingman" dataset from-log "$data/flight-logs/$name/$name.lcmlog" --out "$data/flights" --split "$split" \
      --every 5
    rm -f "$data/flight-logs/$name/$name.lcmlog"
    touch "$data/flight-logs/$name.done"
  done
  touch "$data/flights/.complete"
fi
cat > "$data/combined-flights.yaml" <<EOF
# Stage 3 mix: stage 2's plus the training flights' frames; validation: the clip-disjoint Halmstad val clips.
path: $data
train: [halmstad/images/train, synth/images/train, horizon/images/train, flights/images/train]
val: halmstad/images/val
nc: 1
names: [drone]
EOF
# 6. Stage 3: stage 2's final weights fine-tuned at the shipped input size, 640x352 (the .cfg
# as it is: a 16:9 frame keeps 0.49 of its rows instead of the 416x416 stretch's 0.58 and 0.50 of its columns
# instead of 0.33), at Table 2's 1e-3, 5e-4, 1e-4, 5e-5.
if [ "$train_early" = 1 ] && [ ! -f "$out/stage3/wingman-small_final.weights" ]; then
  u1=$((stage3_batches / 2)) u2=$((stage3_batches * 8 / 10)) u3=$((stage3_batches * 9 / 10))
  resume=()
  [ -f "$out/stage3/checkpoint.pt" ] && resume=(--resume)
  "$bin/wingman" train "${common640[@]}" --data "$data/combined-flights.yaml" --out "$out/stage3" \
    --weights "$out/stage2/wingman-small_final.weights" --max-batches "$stage3_batches" --burn-in 30 \
    --learning-rate 0.001 --steps "$u1,$u2,$u3" --weights-interval 40 "${resume[@]}"
fi
# 7. Stage 4: the shipped cfg, whose third head (stride 32; the stride-16 head sees 99 input pixels, too few for a
# close drone) starts random on stage 3's layers (--partial-weights), the whole network trained on stage 3's data at
# the same rate steps.
[ "$stage4_batches" -gt 0 ] || exit 0
if [ "$train_early" = 1 ] && [ ! -f "$out/stage4/wingman-small_final.weights" ]; then
  u1=$((stage4_batches / 2)) u2=$((stage4_batches * 8 / 10)) u3=$((stage4_batches * 9 / 10))
  resume=()
  [ -f "$out/stage4/checkpoint.pt" ] && resume=(--resume)
  "$bin/wingman" train --cfg "$src/models/wingman-small.cfg" "${augment[@]}" --data "$data/combined-flights.yaml" \
    --out "$out/stage4" --weights "$out/stage3/wingman-small_final.weights" --partial-weights \
    --max-batches "$stage4_batches" --burn-in 30 --learning-rate 0.001 --steps "$u1,$u2,$u3" --weights-interval 100 \
    "${resume[@]}"
fi
[ "$stage5_batches" -gt 0 ] || exit 0
# 8. Stage 5 (shipped until 2026-12-04): stage 4 trained longer, with 2400 more synthetic images added, rendered
# as the synthetic 1280x720 test set is (the simulator's camera size, up to 30 m, antialiased) but from another seed.
render_synth720train
cat > "$data/combined-s5.yaml" <<EOF
# Stage 5 mix: stage 3's plus 2400 synthetic 1280x720 images up to 30 m; validation: the Halmstad val clips.
path: $data
train: [halmstad/images/train, synth/images/train, horizon/images/train, flights/images/train, synth720train/images/train]
val: halmstad/images/val
nc: 1
names: [drone]
EOF
if [ "$train_early" = 1 ] && [ ! -f "$out/stage5/wingman-small_final.weights" ]; then
  u1=$((stage5_batches / 2)) u2=$((stage5_batches * 8 / 10)) u3=$((stage5_batches * 9 / 10))
  resume=()
  [ -f "$out/stage5/checkpoint.pt" ] && resume=(--resume)
  "$bin/wingman" train --cfg "$src/models/wingman-small.cfg" "${augment[@]}" --data "$data/combined-s5.yaml" \
    --out "$out/stage5" --weights "$out/stage4/wingman-small_final.weights" --max-batches "$stage5_batches" \
    --burn-in 30 --learning-rate 0.001 --steps "$u1,$u2,$u3" --weights-interval 100 "${resume[@]}"
fi
if [ "$stage6_batches" -eq 0 ]; then
  [ "$data_only" = 0 ] || echo "train_model: the datasets are ready in $data"
  exit 0
fi
# 9. Stage 6 (three runs of it, the header's commands, give the shipped model): stage 5 trained longer with a
# second set of 2400 synthetic 1280x720 images (seed 41) added, for the synthetic 1280x720 target
# (models/wingman-small.md). With --stage6-mix s5, on stage 5's mix alone (the second set dilutes the training
# flights' small, distant leaders); the shipped model's three runs use s5.
mix6="$data/combined-s6.yaml"
[ "$stage6_mix" = s5 ] && mix6="$data/combined-s5.yaml"
if [ "$stage6_mix" = s6 ] && [ ! -f "$data/synth720train2/data.yaml" ]; then
  rm -rf "$data/synth720train2"
  "$bin/wingman" dataset synth --out "$data/synth720train2" --count 2400 --seed 41 \
    --config "$data/synth720train.yaml" --meshes "$src/../shared/meshes"
fi
cat > "$data/combined-s6.yaml" <<EOF
# Stage 6 mix: stage 5's plus 2400 more synthetic 1280x720 images up to 30 m; validation: the Halmstad val clips.
path: $data
train: [halmstad/images/train, synth/images/train, horizon/images/train, flights/images/train, synth720train/images/train, synth720train2/images/train]
val: halmstad/images/val
nc: 1
names: [drone]
EOF
if [ "$data_only" = 1 ]; then
  echo "train_model: the datasets are ready in $data"
  exit 0
fi
# The box loss: the cfg itself (mse) or a copy with iou_loss/iou_normalizer in every [yolo] section.
# The copy keeps the cfg's name (as cfg-2head/ and cfg-416/ do): the trainer names its outputs after it.
cfg6="$src/models/wingman-small.cfg" out6="$out/stage6"
if [ "$stage6_iou_loss" != mse ]; then
  variant="$stage6_iou_loss"
  [ "$stage6_iou_normalizer" = 0.75 ] || variant="$variant-$stage6_iou_normalizer"
  out6="$out/stage6-$variant"
  mkdir -p "$out/cfg-$variant"
  cfg6="$out/cfg-$variant/wingman-small.cfg"
  sed "s/^\[yolo\]\$/[yolo]\niou_loss=$stage6_iou_loss\niou_normalizer=$stage6_iou_normalizer/" \
    "$src/models/wingman-small.cfg" > "$cfg6"
  [ "$(grep -c "^iou_loss=$stage6_iou_loss\$" "$cfg6")" = "$(grep -c '^\[yolo\]$' "$src/models/wingman-small.cfg")" ] ||
    { echo "train_model: could not write iou_loss into every [yolo] section of $cfg6" >&2; exit 1; }
fi
[ "$stage6_mix" = s5 ] && out6="$out6-s5mix"
ema6=()
if [ -n "$stage6_ema" ]; then
  out6="$out6-ema$stage6_ema"
  ema6=(--ema-decay "$stage6_ema")
fi
[ -f "$out6/wingman-small_final.weights" ] && exit 0
init6="${stage6_init:-$out/stage5/wingman-small_final.weights}"
u1=$((stage6_batches / 2)) u2=$((stage6_batches * 8 / 10)) u3=$((stage6_batches * 9 / 10))
resume=()
[ -f "$out6/checkpoint.pt" ] && resume=(--resume)
exec "$bin/wingman" train --cfg "$cfg6" "${augment[@]}" --data "$mix6" \
  --out "$out6" --weights "$init6" --max-batches "$stage6_batches" \
  --burn-in 30 --learning-rate 0.001 --steps "$u1,$u2,$u3" --weights-interval 100 "${ema6[@]}" "${resume[@]}"

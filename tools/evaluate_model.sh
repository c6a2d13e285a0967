#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Measures a detector model the way its card reports it (models/wingman-small.md): wingman val on the clip-disjoint
# Halmstad val clips (drone clips; airplane, bird and helicopter clips as negatives, false positives per image), on
# the synthetic val split it was trained beside, on a synthetic 1280x720 set up to 30 m, and on the follower's view
# of the formation flights (1280x720, 90 deg, the target on the horizon at 4-20 m, never trained on), on the held-out
# training flight when tools/train_model.sh made them, on synthetic airplanes, birds and helicopters without a drone
# (false positives per image); and its speed (wingman bench detector, at the cfg's size).
# wingman val runs the detector at its default input size (model.input_size auto: the cfg's 640 columns, the rows
# fitted to each set's aspect, 640x512 for the Halmstad frames).
# Then the track-level metrics (wingman val --sequences, docs/training.md): every frame of the Halmstad val clips
# through the detector and wingman-localizer's tracker with the localizer's defaults (as installed: the shipped box
# relation): false tracks per hour of distractor video, drone clips confirmed, time to confirm
# (a few minutes: 4 s a clip on the 2-core VM with the OpenCL backend).
# Writes OUT/*.json (wingman val --json, one pass per set, with every truth not found), OUT/summary.md (the metrics,
# the negative clips' false positives, the truths not found: missed or loose, at the frame's edge, and the track-level
# table), OUT/halmstad_sequences.{txt,json} and OUT/bench.txt.
#
# Usage: tools/evaluate_model.sh [--data DIR] [--cfg CFG] [--weights W] [--out DIR] [--no-bench] [--no-sequences]
#                                [--val-args ARGS]
#   --data     the datasets of tools/train_model.sh (default build/training-data); the 1280x720 set is made there
#   --cfg      default builtin:wingman-small; --weights default builtin:wingman-small (the shipped model)
#   --out      default build/model-eval
#   --no-sequences  leave out the track-level metrics
#   --val-args more wingman val options for every set, one word each (e.g. "--zoom-in --flip-fusion --coarse-pass":
#              the detector's zoom-in, mirrored second pass and half-size pass); default none (the detector's
#              defaults: a single pass)
set -euo pipefail
caller=$(pwd)
cd "$(dirname "$0")/.."
src=$(pwd)
bin="${WINGMAN_BIN_DIR:-$src/build/bin}"
data="$src/build/training-data" cfg=builtin:wingman-small weights=builtin:wingman-small out="$src/build/model-eval"
bench=true sequences=true val_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data="$2"; shift 2 ;;
    --cfg) cfg="$2"; shift 2 ;;
    --weights) weights="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --no-bench) bench=false; shift ;;
    --no-sequences) sequences=false; shift ;;
    --val-args) read -r -a val_args <<<"$2"; shift 2 ;;
    -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "evaluate_model: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
# Relative paths are the caller's; the lists and YAML files written below need absolute ones.
absolute() { case "$1" in /*|builtin:*) echo "$1" ;; *) echo "$caller/$1" ;; esac; }
data=$(absolute "$data") out=$(absolute "$out") cfg=$(absolute "$cfg") weights=$(absolute "$weights")
[ -f "$data/halmstad/data.yaml" ] || { echo "evaluate_model: $data/halmstad is missing: run tools/train_model.sh" >&2; exit 2; }
mkdir -p "$out"

# Halmstad val, per kind of clip (lists of the val split's images, named V_<KIND>_NNN_<frame>.jpg).
for kind in DRONE AIRPLANE BIRD HELICOPTER; do
  (shopt -s nullglob; files=("$data/halmstad/images/val/V_${kind}_"*); [ ${#files[@]} -eq 0 ] || printf '%s\n' "${files[@]}") \
    > "$out/val_$kind.txt"
  "$bin/wingman" dataset mix --out "$out/val_$kind.yaml" --path "$out" --val "val_$kind.txt" > /dev/null
done
val() {  # name data.yaml [args]
  local name="$1" yaml="$2"; shift 2
  echo "evaluate_model: $name" >&2
  "$bin/wingman" val --data "$yaml" --cfg "$cfg" --weights "$weights" --backend opencl "${val_args[@]}" "$@" --json \
    > "$out/$name.json"
}
val halmstad_val "$data/halmstad/data.yaml"
for kind in DRONE AIRPLANE BIRD HELICOPTER; do val "halmstad_val_$kind" "$out/val_$kind.yaml"; done
val synth_val "$data/synth/data.yaml"
# A synthetic 1280x720 set (the simulator's camera) up to 30 m, seed 99: never trained on.
if [ ! -f "$data/synth720/data.yaml" ]; then
  rm -rf "$data/synth720"
  "$bin/wingman" dataset synth --out "$data/synth720" --count 300 --seed 99 --config "$src/config/datasets/synth720.yaml" \
    --meshes "$src/../shared/meshes"
fi
val synth720_val "$data/synth720/data.yaml"
# The follower's view (config/datasets/followview.yaml: config/scenarios/formation_2d.yaml's camera, 1280x720, fx 640,
# ideal pinhole): the leader at the camera's height on the horizon, in front of the treeline, 4-20 m, the shared
# meshes; seed 31: never trained on.
if [ ! -f "$data/followview/data.yaml" ]; then
  rm -rf "$data/followview"
  "$bin/wingman" dataset synth --out "$data/followview" --count 200 --seed 31 \
    --config "$src/config/datasets/followview.yaml" \
    --meshes "$src/../shared/meshes"
fi
val followview_val "$data/followview/data.yaml"
# Synthetic distractors (config/datasets/distractors.yaml: one procedural airplane, bird or helicopter per image and no
# drone, 640x512, 6-60 px; seed 61, never trained on): drone boxes per image, per kind (the label's class).
if [ ! -f "$data/distractors/data.yaml" ]; then
  rm -rf "$data/distractors"
  "$bin/wingman" dataset synth --out "$data/distractors" --count 600 --seed 61 \
    --config "$src/config/datasets/distractors.yaml"
fi
for kind in 1:AIRPLANE 2:BIRD 3:HELICOPTER; do
  (cd "$data/distractors/labels/val" && grep -l "^${kind%%:*} " -- *.txt) |
    sed "s|^\(.*\)\.txt\$|$data/distractors/images/val/\1.jpg|" > "$out/distractors_${kind#*:}.txt"
  "$bin/wingman" dataset mix --out "$out/distractors_${kind#*:}.yaml" --path "$out" --val "distractors_${kind#*:}.txt" \
    --names drone airplane bird helicopter > /dev/null
  val "distractors_${kind#*:}" "$out/distractors_${kind#*:}.yaml"
done
# The held-out training flight (tools/train_model.sh stage 3: flight 7 of seed 1, never trained on), when present.
flights=false
if [ -f "$data/flights/.complete" ]; then
  flights=true
  val flights_val "$data/flights/data.yaml"
fi
if $sequences; then
  # Whole clips, as a flying system meets them (the val split's clips, read from splits.csv; the videos and labels
  # from the shared dataset).
  echo "evaluate_model: halmstad_sequences" >&2
  "$bin/wingman" val --sequences --data "$data/halmstad" --halmstad-root "$src/../shared/datasets/halmstad" \
    --cfg "$cfg" --weights "$weights" --backend opencl \
    "${val_args[@]}" --json "$out/halmstad_sequences.json" > "$out/halmstad_sequences.txt"
fi
if $bench; then
  POCL_AFFINITY=1 "$bin/wingman" bench detector --cfg "$cfg" --weights "$weights" --sizes cfg --threads 1,2 \
    --repetitions 15 > "$out/bench.txt" 2>&1
fi
PYENV_VERSION=system python3 "$src/tools/evaluate_summary.py" "$out" "$flights" "$sequences"

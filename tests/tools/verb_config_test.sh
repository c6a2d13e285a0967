#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Every verb with its options as data (replay, loginfo, make-video, spy, localize, predict, eval, report, bench
# detector, val, import-halmstad, scenario random and sweep, dataset synth here; fly, load and demo-camera in
# fly_config_test.sh) takes `--config FILE` (repeatable), `--set KEY=VALUE` and `--print-config` through common's one
# loader (issue #32): for each, the printed options read back as a file print the same, a flag wins over a file and
# over --set, a --set over a file, and bad keys are all named at once (exit 2). Nothing runs: every call ends at
# --print-config or at the bad key.
# Usage: verb_config_test.sh WINGMAN
set -euo pipefail
wingman="$1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}

# layers "VERB WORDS" "INPUT ARGS" SECTION.NAME --FLAG FILE_VALUE FLAG_VALUE SET_VALUE [text]: the key's printed value
# after each layering (numbers as --print-config prints them; with `text`, the values are printed quoted).
layers() {
  local verb="$1" inputs="$2" key="$3" flag="$4" in_file="$5" in_flag="$6" in_set="$7" q=""
  [ "${8:-}" != text ] || q='"'
  local section=${key%%.*} name=${key#*.} out rc err
  local -a cmd
  read -r -a cmd <<<"$verb $inputs"
  local before=$failures
  printf '%s:\n  %s: %s\n' "$section" "$name" "$in_file" >"$tmp/file.yaml"
  value() { sed -n "/^$section:/,/^\$/s/^  $name: //p" <<<"$1"; }
  expect() {  # WHAT WANT ARGS...
    local what="$1" want="$q$2$q"
    shift 2
    if ! out=$("$wingman" "${cmd[@]}" "$@" --print-config 2>&1); then
      fail "wingman $verb: $what: exit non-zero: $out"
    elif [ "$(value "$out")" != "$want" ]; then
      fail "wingman $verb: $what: $key is '$(value "$out")', expected '$want'"
    fi
  }
  expect "the file" "$in_file" --config "$tmp/file.yaml"
  expect "--set over the file" "$in_set" --config "$tmp/file.yaml" --set "$key=$in_set"
  expect "the flag over the file" "$in_flag" --config "$tmp/file.yaml" "$flag" "$in_flag"
  expect "the flag over --set" "$in_flag" --config "$tmp/file.yaml" --set "$key=$in_set" "$flag" "$in_flag"
  # The printed options are a file of this verb that gives the same options (the header line names the sources; the
  # inputs are given again: scenario random requires --seed and --out on the command line).
  "$wingman" "${cmd[@]}" --config "$tmp/file.yaml" "$flag" "$in_flag" --print-config >"$tmp/printed.yaml"
  "$wingman" "${cmd[@]}" --config "$tmp/printed.yaml" --print-config >"$tmp/again.yaml" ||
    fail "wingman $verb: its printed options do not read back"
  diff <(tail -n +2 "$tmp/printed.yaml") <(tail -n +2 "$tmp/again.yaml") >/dev/null ||
    fail "wingman $verb: its printed options read back differ: $(diff "$tmp/printed.yaml" "$tmp/again.yaml")"
  # Unknown keys: every one named, exit 2 (the first alone, then two at once with a file's).
  printf 'no_section:\n  such_key: 1\n' >"$tmp/bad.yaml"
  rc=0
  err=$("$wingman" "${cmd[@]}" --set no.such_key=1 --print-config 2>&1) || rc=$?
  [ "$rc" = 2 ] || fail "wingman $verb --set no.such_key=1: exit $rc, expected 2 ($err)"
  grep -Fq -- "--set no.such_key: unknown key" <<<"$err" || fail "wingman $verb: the bad key is not named: $err"
  rc=0
  err=$("$wingman" "${cmd[@]}" --config "$tmp/bad.yaml" --set "$section.no_such_key=1" --print-config 2>&1) || rc=$?
  [ "$rc" = 2 ] || fail "wingman $verb with two bad keys: exit $rc, expected 2 ($err)"
  for want in "bad.yaml:2: no_section.such_key: unknown key" "--set $section.no_such_key: unknown key"; do
    grep -Fq -- "$want" <<<"$err" || fail "wingman $verb with two bad keys: '$want' missing in: $err"
  done
  [ "$(wc -l <<<"$err")" = 1 ] || fail "wingman $verb with two bad keys: not one line: $err"
  [ "$failures" != "$before" ] || echo "ok: wingman $verb"
}

layers "replay" "flight.lcmlog" input.max_events --max-events 5 7 9
layers "loginfo" "flight.lcmlog" output.snapshot --snapshot a.png b.png c.png text
layers "make-video" "clip.avi" video.frames --frames 2 3 4
layers "spy" "" spy.java --java java8 java11 java17 text
layers "localize" "cam.yaml --box 1,2,3,4" border.margin_px --border-margin 2.5 3.5 4.5
layers "predict" "a.jpg images" detection.max_detections --max-detections 3 4 5
layers "eval" "flight.lcmlog" eval.leader_id --leader-id 2 3 4
layers "report" "flight.lcmlog -o report.html" report.frames --frames 2 3 4
layers "bench detector" "" bench.repetitions --repetitions 2 3 4
layers "import-halmstad" "halmstad dataset" sample.frame_step --frame-step 2 3 4
layers "val" "--data data.yaml" input.max_images --max-images 2 3 4
if "$wingman" scenario --help >/dev/null 2>&1; then  # a build with the simulator
  layers "scenario random" "--seed 5 --out $tmp/f.yaml" flight.airframe --airframe hex octo quad text
  layers "scenario sweep" "--out $tmp/s.yaml" sweep.frames_per_step --frames-per-step 2 3 4
  layers "dataset synth" "--out $tmp/d --count 3" dataset.seed --seed 5 6 7
fi

# Text and list keys take the same way, and the inputs may come from a file alone.
printf 'input:\n  log: "a flight.lcmlog"\neval:\n  range_bins_m: [1, 2]\nformation:\n  follower_set: [a.b=1]\n' \
  >"$tmp/eval.yaml"
out=$("$wingman" eval --config "$tmp/eval.yaml" --range-bins 3,4,5 --title 'say "hi"' --print-config)
grep -q '^  log: "a flight.lcmlog"$' <<<"$out" || fail "eval: the log from the file: $out"
grep -q '^  range_bins_m: \[3.0, 4.0, 5.0\]$' <<<"$out" || fail "eval: --range-bins over the file: $out"
grep -q '^  follower_set: \["a.b=1"\]$' <<<"$out" || fail "eval: a list of text from the file: $out"
grep -Fq 'title: "say \"hi\""' <<<"$out" || fail "eval: a title with quotes: $out"
# A bad value of a flag is named by its key, with every other problem (exit 2).
rc=0
err=$("$wingman" eval flight.lcmlog --settle -1 --formation-offset 1,2,3 --scenario s.yaml 2>&1) || rc=$?
[ "$rc" = 2 ] || fail "eval with bad values: exit $rc, expected 2 ($err)"
for want in "eval.settle_s = -1: must be >= 0" "formation.offset_m: give it, or the follower's configuration"; do
  grep -Fq -- "$want" <<<"$err" || fail "eval with bad values: '$want' missing in: $err"
done
rc=0
err=$("$wingman" localize --box 1,2,3,4 --radius -1 2>&1) || rc=$?
[ "$rc" = 2 ] || fail "localize without a calibration: exit $rc, expected 2 ($err)"
for want in "input.calibration: give the calibration file" "target.radius_m = -1"; do
  grep -Fq -- "$want" <<<"$err" || fail "localize with bad values: '$want' missing in: $err"
done
exit $((failures > 0))

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `wingman fly --config FILE --set KEY=VALUE` with flags: a flight as data through the one loader, the flags given
# winning over the files and --set, every bad key at once (exit 2). Nothing flies (--print-config). The same layers for
# `wingman load` and `wingman demo-camera`.
# Usage: fly_config_test.sh WINGMAN
set -euo pipefail
wingman="$1"
fail() { echo "fly_config_test: FAIL: $*" >&2; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
printf 'flight:\n  scenario: follow_1d\n  duration_s: 12\nautopilot:\n  kind: mavlink\n' > "$tmp/flight.yaml"
out=$("$wingman" fly --config "$tmp/flight.yaml" --set flight.duration_s=20 --duration 5 --windows \
      --out "$tmp/dir with \"quote\"" --print-config)
grep -q '^  scenario: "follow_1d"$' <<<"$out" || fail "the file's scenario: $out"
grep -q '^  duration_s: 5.0$' <<<"$out" || fail "--duration over --set over the file: $out"
grep -q '^  kind: "mavlink"$' <<<"$out" || fail "the file's autopilot: $out"
grep -q '^  enabled: true$' <<<"$out" || fail "--windows: $out"
grep -Fq "out: \"$tmp/dir with \\\"quote\\\"\"" <<<"$out" || fail "a path with a space and quotes read back as given: $out"
# The effective flight, printed, is a flight file that gives the same flight.
"$wingman" fly --config "$tmp/flight.yaml" --duration 5 --print-config > "$tmp/printed.yaml"
"$wingman" fly --config "$tmp/printed.yaml" --print-config | tail -n +2 > "$tmp/again.yaml"
diff <(tail -n +2 "$tmp/printed.yaml") "$tmp/again.yaml" || fail "a printed flight read back differs"
# Every bad key at once, naming the file and line; exit 2.
printf 'flight:\n  duraton_s: 3\n  detections: radar\n' > "$tmp/bad.yaml"
rc=0
err=$("$wingman" fly --config "$tmp/bad.yaml" --set windows.enabeld=true --print-config 2>&1) || rc=$?
[ "$rc" = 2 ] || fail "a bad flight file: exit $rc, expected 2 ($err)"
for want in "bad.yaml:2: flight.duraton_s: unknown key" "--set windows.enabeld: unknown key" \
            "flight.detections = 'radar': must be cnn or truth"; do
  grep -Fq -e "$want" <<<"$err" || fail "missing '$want' in: $err"
done
# The other launching verbs take the same layers.
printf 'load:\n  cameras: 2\n  mode: replay\n' > "$tmp/load.yaml"
out=$("$wingman" load --config "$tmp/load.yaml" --replay-frames 3 --print-config)
grep -q '^  cameras: 2$' <<<"$out" && grep -q '^  mode: "replay"$' <<<"$out" && grep -q '^  replay_frames: 3$' <<<"$out" ||
  fail "wingman load's layers: $out"
rc=0
err=$("$wingman" load --set load.camera=2 --cameras 9 --print-config 2>&1) || rc=$?
[ "$rc" = 2 ] || fail "wingman load with a bad key and a bad flag: exit $rc ($err)"
# One chain per rig camera: two chains with the four-camera rig is one error naming both keys, before anything runs.
rc=0
rig=$(cd "$(dirname "$0")/../.." && pwd)/config/rigs/surround4.yaml
err=$("$wingman" load --cameras 2 --mode replay --set "load.rig=$rig" --out "$tmp/load" 2>&1) || rc=$?
[ "$rc" = 2 ] || fail "wingman load --cameras 2 with the four-camera rig: exit $rc, expected 2 ($err)"
grep -Fq "load.cameras = 2 and load.rig = $rig: the rig's cameras read DETECTIONS_CAM0, DETECTIONS_CAM1, DETECTIONS_CAM2, DETECTIONS_CAM3" <<<"$err" ||
  fail "wingman load --cameras 2: $err"
[ ! -e "$tmp/load" ] || fail "wingman load --cameras 2 wrote $tmp/load before refusing"
printf 'demo:\n  video: clip.avi\n' > "$tmp/demo.yaml"
out=$("$wingman" demo-camera --config "$tmp/demo.yaml" --print-config)
grep -q '^  video: "clip.avi"$' <<<"$out" || fail "wingman demo-camera's layers: $out"
echo "fly_config_test: ok"

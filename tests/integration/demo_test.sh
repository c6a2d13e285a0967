#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The README's main job, shortened: a 30-frame clip through the real processes on multicast in a
# private network namespace; checks that every frame arrived and every process reported.
set -euo pipefail
src="$1"; bin="$2"
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
"$bin/wingman" make-video "$out/clip.avi" --frames 30 --width 320 --height 240
cd "$src"
# The executables of the build under test (build-tsan's under ThreadSanitizer), not build/bin.
log=$(timeout 120 tools/netns_run.sh "$bin/wingman" demo-camera "$out/clip.avi" --out "$out" --bin-dir "$bin" 2>&1) ||
  { echo "$log"; exit 1; }
echo "$log"
fail() { echo "demo_test: $1" >&2; exit 1; }
echo "$log" | grep -Eq '^IMAGE_CAM0 +image_t +30 ' || fail "expected 30 image_t frames on IMAGE_CAM0"
for p in camera_driver detector localizer follower_ctrl; do
  echo "$log" | grep -Eq "^  $p " || fail "no status from $p"
done
# Every frame reached the detector; in real-time mode it keeps the newest when busy (drops are counted), and the
# shipped model's detections were published for the frames it ran on. Its last status is its periodic OK; DEGRADED
# when 3 s have passed since the clip's last frame (stale input: the demo waits for the detector to settle, and more
# on a loaded machine); or STOPPING, when the logger also caught the heartbeat it sends on SIGTERM at the demo's end.
# Each carries the counts. A detector that failed (ERROR) fails the test.
echo "$log" | grep -Eq "^  detector +(OK|DEGRADED|STOPPING) .*handled 30, drops ([0-9]+)" ||
  fail "detector did not receive all 30 frames"
drops=$(echo "$log" | sed -nE 's/^  detector +(OK|DEGRADED|STOPPING) .*handled 30, drops ([0-9]+).*/\2/p')
echo "$log" | grep -Eq "^DETECTIONS_CAM0 +detections_t +$((30 - drops)) " ||
  fail "expected one detections_t per frame the detector kept (30 - $drops)"
[ -s "$out/last_frame.png" ] || fail "no snapshot written"
echo "demo_test: ok"

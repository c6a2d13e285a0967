#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The demo's pipeline run; call it through tools/netns_run.sh (it refuses to multicast on the host).
# Usage: tools/demo_pipeline.sh VIDEO OUTDIR   (WINGMAN_BIN_DIR: the executables, default build/bin)
set -euo pipefail
[ "${WINGMAN_IN_NETNS:-}" = "1" ] || { echo "demo_pipeline: run me through tools/netns_run.sh" >&2; exit 1; }
video="$1"; out="$2"; bin="${WINGMAN_BIN_DIR:-build/bin}"; url="$WINGMAN_LCM_URL"
log="$out/demo.lcmlog"
pids=()
cleanup() { for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT

echo "demo: LCM bus $url (private network namespace)"
lcm-logger --lcm-url="$url" --force --quiet "$log" & pids+=($!)
"$bin/wingman-detector" --lcm-url "$url" --log-level warn & pids+=($!)
"$bin/wingman-localizer" --lcm-url "$url" --log-level warn & pids+=($!)
"$bin/wingman-follower-ctrl" --lcm-url "$url" --log-level warn & pids+=($!)
# Start-up takes seconds (the detector loads its model and builds its OpenCL kernels): wait, at most 60 s, until
# every process has published its first status heartbeat, which it does once it listens.
for _ in $(seq 120); do
  info=$("$bin/wingman" loginfo "$log" 2>/dev/null || true)
  grep -q "^STATUS_DETECTOR " <<<"$info" && grep -q "^STATUS_LOCALIZER " <<<"$info" &&
    grep -q "^STATUS_FOLLOWER_CTRL " <<<"$info" && break
  sleep 0.5
done

echo "demo: playing $video through wingman-camera-driver"
# Play the clip once at its own rate, stamped by the wall clock like a live camera.
"$bin/wingman-camera-driver" --set source.kind=file --set "file={path: \"$video\", mode: realtime, loop: false}" \
  --lcm-url "$url" --status-period 0.5
# The detector may still be working on the last frames (or building a network for the clip's frame size): wait, at
# most 60 s, until its heartbeat has every frame accounted for (detected or counted as dropped), then one more
# heartbeat from every process.
for _ in $(seq 120); do
  info=$("$bin/wingman" loginfo "$log" 2>/dev/null || true)
  images=$(sed -nE 's/^IMAGE_CAM0 +image_t +([0-9]+) .*/\1/p' <<<"$info")
  dets=$(sed -nE 's/^DETECTIONS_CAM0 +detections_t +([0-9]+) .*/\1/p' <<<"$info")
  handled=$(sed -nE 's/^  detector +[A-Z]+ .*handled ([0-9]+), drops ([0-9]+).*/\1/p' <<<"$info")
  drops=$(sed -nE 's/^  detector +[A-Z]+ .*handled ([0-9]+), drops ([0-9]+).*/\2/p' <<<"$info")
  [ -n "$images" ] && [ "${handled:-0}" -ge "$images" ] && [ $((${dets:-0} + ${drops:-0})) -ge "$images" ] && break
  sleep 0.5
done
sleep 1.2
cleanup
pids=()
trap - EXIT
echo
echo "demo: what arrived on the bus (recorded by lcm-logger in $log):"
"$bin/wingman" loginfo "$log" --snapshot "$out/last_frame.png"

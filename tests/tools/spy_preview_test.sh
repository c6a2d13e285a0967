#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The camera in lcm-spy (issue 34): wingman-camera-driver plays a real 1280x720 frame at 10 Hz for 5 s over udpm, and
# BusCheck (Java LCM, the receiver and classpath of lcm-spy) listens for 15 s: PREVIEW_CAM0 must arrive (at least 4
# previews, 1 Hz) and decode as wingman.image_t. Prints what Java LCM got of IMAGE_CAM0 beside it (Java LCM 1.3.1 ignores
# recv_buf_size: the 2.7 MB frames are mostly lost; not asserted). Run inside tools/netns_run.sh.
# Usage: spy_preview_test.sh SRC_DIR CAMERA_DRIVER JAVA_CLASS_DIR LCM_JAR TYPES_JAR
set -euo pipefail
src="$1" driver="$2" classes="$3" lcm_jar="$4" types_jar="$5"
fail() { echo "spy_preview_test: FAIL: $*" >&2; exit 1; }
[ "${WINGMAN_IN_NETNS:-}" = 1 ] || fail "run me through tools/netns_run.sh (never multicast in the host namespace)"
url="${WINGMAN_LCM_URL:?}"
tmp=$(mktemp -d); trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$tmp"' EXIT
# A 1280x720 frame: a gradient with a dark block (binary PPM, which OpenCV reads).
PYENV_VERSION=system python3 -c '
import sys
w, h = 1280, 720
rows = []
for y in range(h):
    g = y * 255 // h
    row = bytearray()
    for x in range(w):
        dark = 500 <= x < 780 and 260 <= y < 460
        row += bytes((20, 20, 20)) if dark else bytes((x * 255 // w, g, 128))
    rows.append(bytes(row))
with open(sys.argv[1], "wb") as f:
    f.write(b"P6\n%d %d\n255\n" % (w, h))
    f.write(b"".join(rows))
' "$tmp/frame.ppm"
printf 'source: {kind: file}\nfile: {path: "%s", mode: realtime, fps: 10, loop: true}\noutput: {max_frames: 50}\n' \
  "$tmp/frame.ppm" > "$tmp/camera.yaml"
java -cp "$lcm_jar:$types_jar:$classes" BusCheck "$url" 15 > "$tmp/bus.txt" 2> "$tmp/bus.err" &
java_pid=$!
for _ in $(seq 300); do grep -q "BusCheck: listening" "$tmp/bus.txt" 2>/dev/null && break; sleep 0.1; done
grep -q "BusCheck: listening" "$tmp/bus.txt" || { cat "$tmp/bus.err" >&2; fail "BusCheck did not start within 30 s"; }
timeout 30 "$driver" --config "$tmp/camera.yaml" --lcm-url "$url" 2> "$tmp/driver.err" ||
  { cat "$tmp/driver.err" >&2; fail "the camera driver failed"; }
wait "$java_pid" || { cat "$tmp/bus.err" >&2; fail "BusCheck failed"; }
cat "$tmp/bus.txt"
grep -q "50 frames published" "$tmp/driver.err" || { cat "$tmp/driver.err" >&2; fail "the driver did not publish 50 frames"; }
read -r _ type count decoded bytes < <(grep '^PREVIEW_CAM0 ' "$tmp/bus.txt" || echo "PREVIEW_CAM0 - 0 0 0")
[ "$type" = wingman.image_t ] || fail "PREVIEW_CAM0: type '$type' (expected wingman.image_t)"
[ "$count" -ge 4 ] || fail "PREVIEW_CAM0: $count previews reached Java LCM in 5 s (expected >= 4 at 1 Hz)"
[ "$decoded" -eq "$count" ] || fail "PREVIEW_CAM0: $decoded of $count decoded"
images=$(awk '$1 == "IMAGE_CAM0" {print $3}' "$tmp/bus.txt")
echo "spy_preview_test: Java LCM received $count previews (mean $bytes bytes, all decoded) and ${images:-0} of the 50" \
     "1280x720 IMAGE_CAM0 frames"

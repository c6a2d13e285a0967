#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Camera-driver demo. Installs and builds, then plays a short video through wingman-camera-driver
# into the running pipeline (detector, localizer, follower) on LCM multicast inside a private network
# namespace, records the bus, and shows what arrived (`wingman demo-camera`, run by tools/netns_run.sh).
# Usage: tools/demo_camera.sh [VIDEO]   (default: a synthetic clip made by `wingman make-video`;
#        e.g. tools/demo_camera.sh ../shared/datasets/halmstad/videos/V_DRONE_001.mp4 for a real one)
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; exit 0 ;; esac  # help without building
tools/build.sh
out=build/demo
mkdir -p "$out"
video="${1:-}"
if [ -z "$video" ]; then
  video="$out/synthetic.avi"
  build/bin/wingman make-video "$video" --frames 150 --width 640 --height 480
fi
[ -r "$video" ] || { echo "demo: cannot read video '$video'" >&2; exit 1; }
exec tools/netns_run.sh build/bin/wingman demo-camera "$video" --out "$out"

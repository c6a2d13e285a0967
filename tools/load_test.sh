#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Four-camera load test (the thesis's 360-degree case: four networks at once) through the real processes on LCM
# multicast in a private network namespace: `wingman load` (run through tools/netns_run.sh). Each camera N is a
# wingman-camera-driver (camera_N) playing a 1280x720 30 fps clip in a loop on IMAGE_CAM<N>, MJPEG at quality 90 by
# default (--set load.encoding=raw for raw BGR8, --set load.max_width=640 to downscale); a wingman-detector
# (detector_N, the shipped model) detects in it; one wingman-localizer fuses the four cameras (cameras.rig =
# config/rigs/surround4.yaml) into one track set on TARGETS, as the vehicle does; one wingman-follower-ctrl follows
# TARGETS. lcm-logger records every channel but the images; tools/load_summary.py computes the figures and checks.
#
# Usage: tools/load_test.sh [--mode realtime|replay] [--duration S] [--out DIR] [--cameras N]
#                           [--soak] [--warmup S] [--sample-period S] [--replay-frames N] [--max-p99-s S]
#                           [--max-rss-growth-pct P] [--report-only]
#   --cameras N needs a rig of N cameras reading DETECTIONS_CAM0..N-1 (--set load.rig=FILE; the default rig has four);
#   the options of `wingman load` (tools/load_test.sh --help lists them with their defaults and what each mode
#   checks); relative paths are taken from the checkout's root. Environment: WINGMAN_BIN_DIR (default build/bin).
exec "$(dirname "$0")/netns_verb.sh" load "$@"

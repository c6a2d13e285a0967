#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# README's main command: installs what is missing, builds, then flies the thesis's 2-D formation in simulation
# through the real pipeline (wingman-sim, wingman-detector, wingman-localizer, wingman-follower-ctrl as separate
# processes on LCM in a private network namespace), records the bus, prints the localization and formation errors
# and writes an HTML report with the top-down paths. Arguments go to tools/fly.sh (e.g. --scenario follow_1d,
# --render, --duration 30); see tools/fly.sh --help. The camera-driver demo of a video file: tools/demo_camera.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
for a in "$@"; do  # help without building
  case "$a" in -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; echo; exec tools/fly.sh --help ;; esac
done
tools/build.sh
exec tools/fly.sh "$@"

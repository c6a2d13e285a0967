#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Flies a simulated scenario through the real pipeline: `wingman fly` (wingman-sim as camera and autopilot stand-in,
# wingman-detector, wingman-localizer and wingman-follower-ctrl as separate processes on LCM multicast, in lockstep:
# deterministic) inside a private network namespace (tools/netns_run.sh). Records the bus, prints the localization and
# formation errors and writes an HTML report. Needs a build (tools/build.sh); the README's main command (tools/demo.sh)
# builds first.
#
# Usage: tools/fly.sh [--scenario NAME|FILE] [--out DIR] [--duration S] [--detections cnn|truth] [...]
#   the options of `wingman fly` (tools/fly.sh --help lists them with their defaults); relative paths are taken from
#   the checkout's root. WINGMAN_BIN_DIR: the executables (default build/bin). WINGMAN_MODEL_CFG and
#   WINGMAN_MODEL_WEIGHTS: another detector model (wingman fly's --model-cfg and --model-weights).
exec "$(dirname "$0")/netns_verb.sh" fly "$@"

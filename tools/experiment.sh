#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs experiments (config/experiments/NAME.yaml: the thesis's experiments in simulation and the out-of-sample suite)
# with the shipped detector model and the real processes: `wingman experiment` inside a private network namespace
# (tools/netns_run.sh). Each flight is a `wingman fly` (wingman-sim renders 1280x720 images; wingman-detector,
# -localizer and -follower-ctrl run as separate processes on LCM, in lockstep); each experiment writes its flights
# (log, eval.json, report.html), results.json and results.md (the thesis's figures beside ours) in
# build/experiments/NAME/ (docs/results.md collects them).
#
# Usage: tools/experiment.sh NAME... [--quick] [--out DIR] [--detections cnn|truth] [--duration S] [--dry-run]
#   tools/experiment.sh --list      the experiments and what each measures
#   tools/experiment.sh --help      every option with its default
# WINGMAN_BIN_DIR: the executables (default build/bin). WINGMAN_SHARED_MESHES: the four shared airframes (default
# ../shared/meshes; without them the suite flies its procedural stand-ins).
exec "$(dirname "$0")/netns_verb.sh" experiment "$@"

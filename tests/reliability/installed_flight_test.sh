#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# What is installed is what is flown: installs the build into a temporary prefix (cmake --install), then flies the
# README's formation (config/scenarios/formation_2d.yaml, the CNN on rendered images, 12 s) with the INSTALLED
# executables (WINGMAN_BIN_DIR=PREFIX/bin) and the INSTALLED localizer and follower configurations
# (PREFIX/etc/wingman/*.yaml, the files the supervisor and systemd units run), through tools/fly.sh in its own
# network namespace, and checks the flight against stated bounds. The installed configurations must be the shipped
# files (config/*.yaml).
# Bounds (this flight measured 0.339 m RMS, formation 0.220 m, 351 estimates of 360 frames, 1 id, 0 false targets):
#   localization RMS <= 0.45 m; formation RMS <= 0.60 m; target estimates >= 90 % of the frames the leader is
#   visible in; exactly one track id on the leader; no false target.
# Usage: tests/reliability/installed_flight_test.sh SRC_DIR BUILD_DIR [WORK_DIR]
set -euo pipefail
src=$(cd "$1" && pwd) build=$(cd "$2" && pwd)
work="${3:-$(mktemp -d /tmp/wingman-installed-flight.XXXXXX)}"
[ -n "${3:-}" ] || trap 'rm -rf "$work"' EXIT
fail() { echo "installed_flight: FAIL: $*" >&2; exit 1; }
export PYENV_VERSION=system
prefix="$work/prefix"
rm -rf "$prefix" "$work/flight"
mkdir -p "$work"
cmake --install "$build" --prefix "$prefix" > "$work/install.log" 2>&1 || { cat "$work/install.log" >&2; fail "cmake --install"; }
etc="$prefix/etc/wingman"
# The installed configurations are the shipped files, byte for byte (test_process_runtime checks that each equals its
# process's built-in defaults: the built-in shipped model for the detector, the one fly.sh's detector runs).
for f in localizer follower_ctrl detector; do
  [ -r "$etc/$f.yaml" ] || fail "$etc/$f.yaml is not installed"
  cmp -s "$etc/$f.yaml" "$src/config/$f.yaml" || fail "$etc/$f.yaml differs from config/$f.yaml"
done

WINGMAN_BIN_DIR="$prefix/bin" "$src/tools/fly.sh" --out "$work/flight" --duration 12 \
  --localizer-config "$etc/localizer.yaml" --follower-config "$etc/follower_ctrl.yaml" > "$work/fly.log" 2>&1 ||
  { tail -40 "$work/fly.log" >&2; fail "tools/fly.sh with the installed stack"; }

PYTHONPATH="$src/tests/support" python3 - "$work/flight/eval.json" <<'PY'
import json, sys
from bounds import check, installed_flight_checks
e = json.load(open(sys.argv[1]))
check("installed_flight", installed_flight_checks(e))
PY
echo "installed_flight: the installed stack ($prefix) flew within the bounds"

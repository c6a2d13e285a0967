#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# README's test command: installs what is missing, builds, and runs every test with CTest.
# Multi-process tests run in private network namespaces (tools/netns_run.sh); nothing multicasts on
# the host. Tests that read ../shared skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/build.sh
export POCL_AFFINITY=1 OMP_WAIT_POLICY=PASSIVE OPENBLAS_NUM_THREADS=1
ctest --test-dir build --output-on-failure -j2 --timeout 900 "$@"

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# README's test command: installs what is missing, builds, and runs every test with CTest, then the sanitizer
# stages (tools/sanitize.sh).
# Multi-process tests run in private network namespaces (tools/netns_run.sh); nothing multicasts on
# the host. Tests that read ../shared skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in  # help without building
  -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; echo "Arguments (a selection) go to ctest, e.g. tools/test.sh -R Localizer."; exit 0 ;;
esac
# shellcheck source=tools/lib/stage.sh
. tools/lib/stage.sh  # stage PREFIX NAME CMD...: runs CMD and prints its wall time
stage test "install and build" tools/build.sh
export POCL_AFFINITY=1 OMP_WAIT_POLICY=PASSIVE OPENBLAS_NUM_THREADS=1
stage test ctest ctest --test-dir build --output-on-failure -j2 --timeout 900 "$@"
# With ctest arguments (a selection), only that selection runs. Otherwise the sanitizer stages follow
# (docs/reliability.md): the suite under AddressSanitizer + UndefinedBehaviorSanitizer with the libFuzzer targets
# given WINGMAN_FUZZ_RUNS inputs each from a fixed seed (default 100000, at most WINGMAN_FUZZ_SECONDS), then the
# multi-process and threaded tests under ThreadSanitizer.
# WINGMAN_SKIP_SANITIZERS=1 skips them.
if [ $# -eq 0 ] && [ "${WINGMAN_SKIP_SANITIZERS:-0}" != 1 ]; then
  tools/sanitize.sh asan
  tools/sanitize.sh tsan
fi

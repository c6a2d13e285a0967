#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs one libFuzzer target for a bounded time on a temporary copy of its seed corpus (ctest fuzz.<target>).
# Usage: run_fuzzer.sh FUZZER CORPUS_DIR SECONDS ARTIFACT_DIR [extra libFuzzer flags...]
# Fails on any finding: crash, sanitizer report, an input over 10 s (-timeout), an allocation over 512 MB
# (-malloc_limit_mb) or RSS over 2 GB (-rss_limit_mb). The crashing input lands in ARTIFACT_DIR; reproduce with
# `FUZZER ARTIFACT_DIR/crash-...`. Prints libFuzzer's final stats (executions, exec/s).
# The random seed is WINGMAN_FUZZ_SEED (default 1), so a CI run explores the same inputs each time; with -runs=N among
# the extra flags (ctest passes WINGMAN_FUZZ_RUNS) it also stops at the same input on any machine that finishes
# within SECONDS. Set WINGMAN_FUZZ_SEED=0 for a random seed, as in long runs by hand.
set -euo pipefail
if [[ $# -lt 4 ]]; then
  echo "usage: $0 FUZZER CORPUS_DIR SECONDS ARTIFACT_DIR [libFuzzer flags...]" >&2
  exit 2
fi
fuzzer=$1
corpus=$2
seconds=$3
artifacts=$4
shift 4
work=$(mktemp -d "${TMPDIR:-/tmp}/wingman-fuzz.XXXXXX")
trap 'rm -rf "$work"' EXIT
cp -r "$corpus"/. "$work"/
mkdir -p "$artifacts"
# ASAN_OPTIONS from the caller (tools/sanitize.sh) are kept; libFuzzer needs the allocator to report, not return
# null, so a huge allocation is a finding.
"$fuzzer" -max_total_time="$seconds" -rss_limit_mb=2048 -malloc_limit_mb=512 -timeout=10 -print_final_stats=1 \
  -seed="${WINGMAN_FUZZ_SEED:-1}" -artifact_prefix="$artifacts/" "$@" "$work"

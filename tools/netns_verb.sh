#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs `wingman VERB ARGS...` from the checkout's root inside a private network namespace (tools/netns_run.sh: LCM
# multicast on its loopback only), with --bin-dir; `--help` and `--list` answer outside it. The launchers' wrappers
# (tools/fly.sh, tools/load_test.sh, tools/experiment.sh) are this with their verb.
# Usage: tools/netns_verb.sh VERB [ARGS...]. WINGMAN_BIN_DIR: the executables (default build/bin).
set -euo pipefail
cd "$(dirname "$0")/.."
verb="${1:?usage: tools/netns_verb.sh VERB [ARGS...]}"
shift
bin="${WINGMAN_BIN_DIR:-$(pwd)/build/bin}"
[ -x "$bin/wingman" ] || { echo "$verb: $bin/wingman is missing: build first (tools/build.sh)" >&2; exit 2; }
export PYENV_VERSION=system  # the verbs' Python summaries use Debian's python3
for a in "$@"; do
  case "$a" in -h|--help|--list) exec "$bin/wingman" "$verb" "$@" ;; esac
done
exec tools/netns_run.sh "$bin/wingman" "$verb" --bin-dir "$bin" "$@"

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Every `wingman` verb's --help shows its options' defaults from the variables they are bound to (the options
# structs), not hand-typed "(default X)" texts that drift from them (issue #32): each verb's and subverb's help has no
# "(default", no empty list "=[]" and no default on a REQUIRED option, and a few known defaults appear.
# Usage: cli_help_test.sh WINGMAN
set -euo pipefail
wingman="$1"
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}
subcommands() { sed -n '/^Subcommands:/,$p' | awk 'NR > 1 && /^  [a-z]/ {print $1}'; }

# Each verb's and subverb's help, read once (each start of wingman takes about a second).
declare -A help
verbs=()
read_help() {
  # shellcheck disable=SC2086  # "verb sub" is two arguments
  if help[$1]=$("$wingman" $1 --help 2>&1); then verbs+=("$1"); else fail "wingman $1 --help exits non-zero"; fi
}
for verb in $("$wingman" --help | subcommands); do
  read_help "$verb"
  for sub in $(subcommands <<<"${help[$verb]:-}"); do read_help "$verb $sub"; done
done
[ "${#verbs[@]}" -ge 20 ] || fail "only ${#verbs[@]} verbs and subverbs found in wingman --help: ${verbs[*]}"

for v in "${verbs[@]}"; do
  if grep -n "(default" <<<"${help[$v]}"; then fail "wingman $v --help: a hand-typed default (above)"; fi
  if grep -n "=\[\]" <<<"${help[$v]}"; then fail "wingman $v --help: an empty list shown as a default (above)"; fi
  if grep -nE "^  [^ ]+ [^ ]+=.* REQUIRED" <<<"${help[$v]}"; then
    fail "wingman $v --help: a required option with a default (above)"
  fi
done

# The help shows what the program does: these are the structs' defaults.
expect() {
  local v="$1" line="$2"
  if grep -qF -- "$line" <<<"${help[$v]:-}"; then
    echo "ok: wingman $v --help: $line"
  else
    fail "wingman $v --help has no '$line':"
    echo "${help[$v]:-}"
  fi
}
expect train "--checkpoint-interval INT=100"
expect train "--batch INT=64"
expect train "--steps INT=[10000,20000,30000]"
expect val "--backend TEXT=auto"
expect val "--p-thresh FLOAT=0.005"
expect predict "--p-thresh FLOAT=0.2"
expect predict "--weights TEXT=builtin:wingman-small"
expect "bench detector" "--sizes TEXT=[416,320,256]"
expect localize "--radius FLOAT=0.348"
expect eval "--title TEXT=\"Wingman flight\""
expect replay "--speed FLOAT=1"
expect import-halmstad "--exclude TEXT=[V_DRONE_005,V_DRONE_099]"
if [ -n "${help[scenario random]:-}" ]; then expect "scenario random" "--seed UINT REQUIRED"; fi
exit $((failures > 0))

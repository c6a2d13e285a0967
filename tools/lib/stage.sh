# SPDX-License-Identifier: MIT
# shellcheck shell=bash
# Sourced by tools/test.sh and tools/sanitize.sh: stage PREFIX NAME CMD... runs CMD, prints
# "PREFIX: NAME took N s (exit RC)" (so that a CI log says where its time went) and returns CMD's exit status.
stage() {
  local prefix=$1 name=$2 start rc=0
  shift 2
  start=$(date +%s)
  "$@" || rc=$?
  echo "$prefix: $name took $(($(date +%s) - start)) s (exit $rc)"
  return $rc
}

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The two Python examples as installed: `cmake --install --component python` into a temporary prefix, then
# log_summary on a C++-written flight log (counts against `wingman loginfo`) and print_targets on TARGETS that a C++
# program publishes. Runs inside tools/netns_run.sh (multicast only in a private network namespace).
# Usage: tools/netns_run.sh examples_test.sh CMAKE BUILD_DIR BUS_PEER WINGMAN WRITE_REPORT_FLIGHT
set -euo pipefail
cmake="$1" build="$2" peer="$3" wingman="$4" write_flight="$5"
[ "${WINGMAN_IN_NETNS:-}" = "1" ] || { echo "examples_test: run me through tools/netns_run.sh" >&2; exit 1; }
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "examples_test: FAIL: $*" >&2; exit 1; }
export PYENV_VERSION=system PYTHONDONTWRITEBYTECODE=1

"$cmake" --install "$build" --prefix "$work/prefix" --component python > "$work/install.txt"
site="$work/prefix/lib/python3/dist-packages"
for f in wingman/__init__.py wingman/targets_t.py wingman/image_t.py wingman_lcm/__init__.py wingman_lcm/log.py \
         wingman_lcm/udpm.py wingman_lcm/examples/print_targets.py wingman_lcm/examples/log_summary.py; do
  [ -f "$site/$f" ] || fail "not installed: $site/$f"
done
export PYTHONPATH="$site"
python3 -c "import wingman, wingman_lcm; assert wingman_lcm.__file__.startswith('$site'), wingman_lcm.__file__"
echo "ok   installed in $site"

# log_summary: per channel the count loginfo gives, and utimes of the decoded messages.
"$write_flight" "$work/flight.lcmlog"
python3 -m wingman_lcm.examples.log_summary "$work/flight.lcmlog" > "$work/summary.txt"
"$wingman" loginfo "$work/flight.lcmlog" > "$work/loginfo.txt"
cat "$work/summary.txt"
ours=$(awk '{print $1, $2, $3}' "$work/summary.txt" | sort)
theirs=$(awk 'NR > 1 && NF == 6 {print $1, $2, $3}' "$work/loginfo.txt" | sort)
[ -n "$ours" ] && [ "$ours" = "$theirs" ] || fail "log_summary's channels, types and counts differ from loginfo's:
$ours
---
$theirs"
awk '$4 <= 0 || $5 < $4 {exit 1}' "$work/summary.txt" || fail "log_summary: a first utime after the last"
echo "ok   log_summary: channels, types and counts as loginfo's"

# print_targets: 3 TARGETS messages (two targets each) of a C++ publisher sending 20 rounds, 100 ms apart.
timeout 30 python3 -m wingman_lcm.examples.print_targets "$WINGMAN_LCM_URL" 3 15 > "$work/targets.txt" &
example=$!
sleep 1  # the example has subscribed
"$peer" publish "$WINGMAN_LCM_URL" "$work/sent.lcmlog" 20 100
wait "$example" || fail "print_targets exited $?"
cat "$work/targets.txt"
[ "$(wc -l < "$work/targets.txt")" -eq 6 ] || fail "print_targets: not 6 lines (3 messages of 2 targets)"
grep -Eq '^utime [0-9]+ track [0-9]*1 world \(1\.50, [0-9]+\.00, 10\.25\) m$' "$work/targets.txt" \
  || fail "print_targets: no first target at (1.50, y, 10.25)"
grep -Eq '^utime [0-9]+ track [0-9]*2 world \(2\.50, [0-9]+\.00, 10\.25\) m$' "$work/targets.txt" \
  || fail "print_targets: no second target at (2.50, y, 10.25)"
echo "ok   print_targets: 3 messages, each target's id and world position"
echo "examples_test: all checks passed"

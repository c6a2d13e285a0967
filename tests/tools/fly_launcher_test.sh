#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `wingman fly` as a launcher, with the real processes in a private network namespace (run through tools/netns_run.sh):
#  1. a pipeline process that ends during the flight (a wingman-localizer stand-in that exits 3 after its start) fails
#     the flight with exit 1 and a line naming it, and no process of the flight is left running;
#  2. SIGINT to wingman fly mid-flight stops the flight with exit 130, and no process is left running;
#  3. a short ground-truth flight through the real binaries scores its log (eval's table, eval.json, report.html).
# Usage: fly_launcher_test.sh SOURCE_DIR BIN_DIR
set -euo pipefail
src="$1"; bin="$2"
fail() { echo "fly_launcher_test: FAIL: $*" >&2; exit 1; }
[ "${WINGMAN_IN_NETNS:-}" = "1" ] || fail "run me through tools/netns_run.sh"
work=$(mktemp -d)
trap 'pkill -KILL -f "$work/" 2>/dev/null || true; rm -rf "$work"' EXIT
# Every process of a flight runs from $work/bin (links to the real executables), so `pgrep -f $work/` finds them all.
mkdir -p "$work/bin"
for exe in wingman-sim wingman-detector wingman-localizer wingman-follower-ctrl wingman; do ln -s "$bin/$exe" "$work/bin/$exe"; done
left_running() { pgrep -f "$work/bin/" | grep -v "^$$\$" || true; }
cd "$src"

# 1. The localizer stand-in: starts, then ends with 3 (as a crashing process would) while the simulator waits for it.
rm "$work/bin/wingman-localizer"
printf '#!/usr/bin/env bash\nsleep 1\nexit 3\n' > "$work/bin/wingman-localizer"
chmod +x "$work/bin/wingman-localizer"
rc=0
out=$(timeout 120 "$bin/wingman" fly --bin-dir "$work/bin" --detections truth --duration 5 --out "$work/f1" 2>&1) || rc=$?
[ "$rc" = 1 ] || { echo "$out"; fail "a pipeline process ended: exit $rc, expected 1"; }
grep -q "fly: wingman-localizer ended (exit 3) while the flight ran" <<<"$out" || { echo "$out"; fail "no line naming the localizer"; }
[ -z "$(left_running)" ] || fail "processes left running after the failed flight: $(left_running)"
echo "fly_launcher_test: 1. the ended localizer failed the flight (exit 1), named, nothing left running"
rm "$work/bin/wingman-localizer"; ln -s "$bin/wingman-localizer" "$work/bin/wingman-localizer"

# 2. SIGINT mid-flight (a 60-s rendered CNN flight, interrupted once the simulator flies).
"$bin/wingman" fly --bin-dir "$work/bin" --duration 60 --out "$work/f2" > "$work/f2.log" 2>&1 &
fly_pid=$!
for _ in $(seq 600); do grep -q "frames at 30 Hz" "$work/f2.log" 2>/dev/null && break; sleep 0.1; done
grep -q "frames at 30 Hz" "$work/f2.log" || { cat "$work/f2.log"; kill -KILL "$fly_pid"; fail "the flight did not start within 60 s"; }
kill -INT "$fly_pid"
rc=0
for _ in $(seq 300); do kill -0 "$fly_pid" 2>/dev/null || break; sleep 0.1; done
kill -0 "$fly_pid" 2>/dev/null && { kill -KILL "$fly_pid"; fail "wingman fly still running 30 s after SIGINT"; }
wait "$fly_pid" || rc=$?
[ "$rc" = 130 ] || { cat "$work/f2.log"; fail "interrupted flight: exit $rc, expected 130"; }
grep -q "fly: stopped by signal 2" "$work/f2.log" || { cat "$work/f2.log"; fail "no line saying the flight was stopped"; }
[ -z "$(left_running)" ] || fail "processes left running after SIGINT: $(left_running)"
echo "fly_launcher_test: 2. SIGINT stopped the flight (exit 130), nothing left running"

# 3. A short ground-truth flight, scored.
out=$(timeout 300 "$bin/wingman" fly --bin-dir "$work/bin" --detections truth --duration 3 --out "$work/f3" 2>&1) ||
  { echo "$out"; fail "the ground-truth flight failed"; }
grep -q "flown in .* s of wall-clock time; errors against ground truth" <<<"$out" || { echo "$out"; fail "no eval line"; }
grep -q "localization" <<<"$out" || { echo "$out"; fail "no localization figures"; }
for f in flight.lcmlog sim.yaml eval.json targets.csv report.html; do
  [ -s "$work/f3/$f" ] || fail "$f missing from the flight's folder"
done
[ -z "$(left_running)" ] || fail "processes left running after the flight: $(left_running)"
echo "fly_launcher_test: 3. a 3-s flight flown and scored; nothing left running"

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Supervision fault test (issue 8, items 1-2): the four pipeline processes run under supervisord with the shipped
# config/supervisor/wingman.conf (rendered for the build tree by tools/supervise.sh), a simulated flight runs in real
# time (wingman-sim renders the camera, the detector runs the shipped CNN), and each supervised process is killed
# with SIGKILL in turn. For each it checks, inside a private network namespace (tools/netns_run.sh):
#  - supervisord restarts it (a new pid);
#  - the pipeline works again within the restart bound (wall time after the restart; the issue's target is 2 s, the
#    test's bound is generous, 20 s by default, as the shared 2-core machine is noisy; each line of the figures says
#    whether the 2 s target was met):
#    camera driver: its images (a looped clip from `wingman make-video` on its own channel IMAGE_SUPCAM) resume;
#    detector, localizer: a TARGETS message with a target whose newest image is newer than every detection seen
#    before the kill; follower: setpoints resume;
#  - no other supervised process crashed (same pids, no other exit in supervisord's log);
#  - localizer: every setpoint between the last targets before the kill (plus hold.timeout_s) and the first fresh
#    target after the restart is a MODE_HOLD (message time from the messages, not the receive clock).
# It first measures the CNN's detection rate on the flight (frames with a box / frames). It prints the measured
# figures at the end (restart time, time to the first target after the restart, holds).
#
# Usage: tests/reliability/supervisor_fault_test.sh SRC_DIR BIN_DIR TESTS_BIN_DIR
# Environment (for runs by hand): WINGMAN_FAULT_SPEED (sync.speed, default 0.5), WINGMAN_FAULT_ROUNDS (kill rounds
# over the four processes, default 1), WINGMAN_FAULT_BOUND_S (restart bound, default 20), WINGMAN_FAULT_KEEP=1 keeps
# the temporary folder (logs, rendered configs, bus trace). Exits 77 (skipped) without supervisord.
set -euo pipefail
src=$(cd "$1" && pwd) bin=$(cd "$2" && pwd) tbin=$(cd "$3" && pwd)
if [ "${WINGMAN_IN_NETNS:-}" != "1" ]; then exec "$src/tools/netns_run.sh" "$0" "$@"; fi
if ! command -v supervisord > /dev/null || ! command -v supervisorctl > /dev/null; then
  echo "supervisor_fault_test: SKIPPED: supervisord is not installed (tools/install_deps.sh installs Debian's supervisor)"
  exit 77
fi
for exe in wingman-camera-driver wingman-detector wingman-localizer wingman-follower-ctrl wingman-sim wingman; do
  [ -x "$bin/$exe" ] || { echo "supervisor_fault_test: $bin/$exe is missing (build first)" >&2; exit 2; }
done
[ -x "$tbin/wingman-bus-watch" ] || { echo "supervisor_fault_test: $tbin/wingman-bus-watch is missing" >&2; exit 2; }

speed="${WINGMAN_FAULT_SPEED:-0.5}" rounds="${WINGMAN_FAULT_ROUNDS:-1}" bound_s="${WINGMAN_FAULT_BOUND_S:-20}"
target_s=2  # the issue's figure: reported, not asserted
hold_timeout_s=0.15  # the follower's hold.timeout_s (default 0.5): short, so that the localizer's outage, a second or two of
# wall time but only 0.2-0.5 s of message time here (the simulator renders slower than sync.speed asks), outlasts it
url="$WINGMAN_LCM_URL"
tmp=$(mktemp -d /tmp/wingman-supervisor-fault.XXXXXX)
export POCL_AFFINITY=1 OMP_WAIT_POLICY=PASSIVE OPENBLAS_NUM_THREADS=1
sup_pid="" sim_pid="" watch_pid=""
SECONDS=0
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
now_us() { date +%s%6N; }

# Stops what this test started, each by its pid, bounded in time.
stop_pid() {
  local pid="$1" _
  [ -n "$pid" ] || return 0
  kill -TERM "$pid" 2>/dev/null || return 0
  for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}
cleanup() {
  stop_pid "$sim_pid"
  stop_pid "$sup_pid"  # supervisord stops its programs (SIGTERM, stopwaitsecs) before it exits
  stop_pid "$watch_pid"
  if [ "${WINGMAN_FAULT_KEEP:-}" = 1 ]; then echo "supervisor_fault_test: kept $tmp"; else rm -rf "$tmp"; fi
}
trap cleanup EXIT

# --- The processes' configurations (the installed layout's etc folder, here a temporary one) ---
etc="$tmp/etc"
mkdir -p "$etc"
"$bin/wingman" make-video --frames 60 --width 320 --height 240 --fps 10 "$tmp/clip.avi" > /dev/null 2>&1
cat > "$etc/camera_driver.yaml" <<YAML
# The camera is the simulator in this flight: the supervised driver plays a looped clip on its own channel.
source: {kind: file}
file: {path: "$tmp/clip.avi", mode: realtime, fps: 10, loop: true}
output: {channel: IMAGE_SUPCAM, camera_id: 1}
YAML
cat > "$etc/detector.yaml" <<YAML
input: {mode: realtime}
# opencl, not auto: auto times both backends at every start (seconds here), which a restart should not wait for.
model: {cfg: "builtin:wingman-small", weights: "builtin:wingman-small", backend: opencl}
YAML
# The simulator's camera; the target's size and the box relation at their defaults (as installed).
cat > "$etc/localizer.yaml" <<YAML
camera: {width: 640, height: 360, focal_px: 320.0}
YAML
cat > "$etc/follower_ctrl.yaml" <<YAML
hold: {timeout_s: $hold_timeout_s}
formation: {offset_m: [0.0, -4.0, 0.0]}
localizer: {instance: localizer}
YAML
# The recorder at its defaults: recordings/ in its working directory, the log folder (tools/supervise.sh makes it).
printf 'output: {directory: "recordings"}\n' > "$etc/recorder.yaml"
# The MAVLink bridge at its defaults: it listens for an autopilot on UDP 14540 (none comes; it stays DEGRADED).
cp "$src/config/mavlink_bridge.yaml" "$etc/mavlink_bridge.yaml"
"$src/tools/supervise.sh" --bin "$bin" --etc "$etc" --lcm-url "$url" --standalone "$tmp/sup" > /dev/null
conf="$tmp/sup/supervisord.conf" suplog="$tmp/sup/supervisord.log"
# The rendered file is the shipped one with the paths substituted: same lines otherwise.
if ! diff <(sed -e "s|$bin/|/usr/local/bin/|g" -e "s|$etc/|/usr/local/etc/wingman/|g" -e "s|$tmp/sup/log/|/var/log/wingman/|g" \
               -e "s|$url|udpm://239.255.76.67:7667?ttl=0\&recv_buf_size=4194304|g" "$tmp/sup/wingman.conf") \
          "$src/config/supervisor/wingman.conf" > "$tmp/render.diff"; then
  fail "tools/supervise.sh changed more than the paths and URL:"; cat "$tmp/render.diff"
fi

programs=(wingman-camera-driver wingman-detector wingman-localizer wingman-follower-ctrl)
# The newest pid supervisord spawned for a program ("" if none), and how many times it spawned it.
pid_of() { { grep -o "spawned: '$1' with pid [0-9]*" "$suplog" || true; } | tail -n 1 | sed 's/.* pid //'; }
spawns_of() { { grep -c "spawned: '$1' with pid" "$suplog" || true; } | head -n 1; }
exits_of() { { grep -c "exited: $1 " "$suplog" || true; } | head -n 1; }
# Wall time (us) of the newest "spawned: NAME" line of supervisord's log (local time, milliseconds).
spawn_time_us() {
  local line stamp
  line=$(grep "spawned: '$1' with pid" "$suplog" | tail -n 1)
  stamp=$(echo "$line" | awk '{print $1" "$2}' | tr ',' '.')
  echo $(( $(date -d "$stamp" +%s%3N) * 1000 ))
}
# wait_for LIMIT_S COMMAND [ARGS...]: runs the command every 0.1 s until it succeeds, for LIMIT_S seconds at most.
# Every wait also ends at the test's own deadline (480 s of wall time), well before CTest's TIMEOUT.
wait_for() {
  local limit="$1" _
  shift
  for _ in $(seq 1 $((limit * 10))); do
    "$@" && return 0
    [ "$SECONDS" -lt 480 ] || { echo "supervisor_fault_test: the test's 480 s deadline has passed"; return 1; }
    sleep 0.1
  done
  return 1
}
all_running() {
  local p
  for p in "${programs[@]}"; do grep -q "success: $p entered RUNNING" "$suplog" 2>/dev/null || return 1; done
}

# --- Start: the bus watcher, supervisord, the simulated flight ---
bus="$tmp/bus.txt"
"$tbin/wingman-bus-watch" --lcm-url "$url" --image IMAGE_SUPCAM --seconds 590 > "$bus" 2> "$tmp/bus.err" &
watch_pid=$!
supervisord -n -c "$conf" > "$tmp/sup/stdout.txt" 2>&1 &
sup_pid=$!
wait_for 60 all_running || { fail "the four programs did not reach RUNNING within 60 s"; cat "$suplog"; exit 1; }
echo "supervisor_fault_test: supervisord runs the four programs (config rendered from config/supervisor/wingman.conf)"

cat > "$tmp/sim.yaml" <<YAML
scenario: {file: "$src/tests/reliability/hover_close.yaml"}
camera: {width: 640, height: 360, focal_px: 320.0, rate_hz: 30.0}
sync: {mode: realtime, speed: $speed, wait_for: [detector, localizer, follower_ctrl], startup_timeout_s: 120.0}
render: {enabled: true, supersampling: 1}
YAML
"$bin/wingman-sim" --lcm-url "$url" --config "$tmp/sim.yaml" --log-level warn > "$tmp/sim.txt" 2>&1 &
sim_pid=$!

# TARGETS lines with a target whose newest image is newer than $1 (message time), received at or after $2 (wall us).
fresh_targets() { awk -v s="$1" -v w="$2" '$2 == "TARGETS" && $4 > 0 && $5 > s && $1 >= w' "$bus"; }
first_fresh_target_wall() { fresh_targets "$1" "$2" | head -n 1 | awk '{print $1}'; }
# Whether a fresh target (newer than message time $1) arrived at or after wall time $2.
has_fresh_target() { [ -n "$(first_fresh_target_wall "$1" "$2")" ]; }
# Whether a fresh target arrived in the last 2 s of wall time.
targets_steady() { has_fresh_target 0 $(($(now_us) - 2000000)); }
# Whether supervisord spawned program $1 more than $2 times.
respawned() { [ "$(spawns_of "$1")" -gt "$2" ]; }
has_evidence() { [ -n "$(evidence)" ]; }

if ! wait_for 180 has_fresh_target 0 0; then
  fail "no TARGETS with a target within 180 s of the flight's start"; tail -n 20 "$tmp/sim.txt"; exit 1
fi
echo "supervisor_fault_test: targets flow; measuring the detection rate for 10 s"
t0=$(now_us); sleep 10; t1=$(now_us)
read -r frames with_box <<< "$(awk -v a="$t0" -v b="$t1" '$2 == "DETECTIONS" && $1 >= a && $1 < b {n++; if ($6 > 0) k++}
                                END {print n + 0, k + 0}' "$bus")"
det_rate=$(awk -v n="$frames" -v k="$with_box" 'BEGIN {printf "%.1f", n ? 100 * k / n : 0}')
echo "supervisor_fault_test: detection rate $det_rate % ($with_box of $frames detections messages with a box in 10 s," \
     "$(awk -v n="$frames" 'BEGIN {printf "%.1f", n / 10}') frames/s)"

summary=()
for _ in $(seq 1 "$rounds"); do
  for prog in "${programs[@]}"; do
    # Steady state first: a fresh target (or, for the camera, an image) in the last 2 s.
    wait_for 60 targets_steady || { fail "$prog: no steady targets before the kill"; exit 1; }
    declare -A before_pid=() before_exits=()
    for p in "${programs[@]}"; do before_pid[$p]=$(pid_of "$p"); before_exits[$p]=$(exits_of "$p"); done
    spawns=$(spawns_of "$prog")
    last_det_utime=$(awk '$2 == "DETECTIONS" {u = $4} END {printf "%.0f\n", u}' "$bus")
    last_targets_utime=$(awk '$2 == "TARGETS" {u = $3} END {printf "%.0f\n", u}' "$bus")
    t_kill=$(now_us)
    kill -KILL "${before_pid[$prog]}"
    if ! wait_for 30 respawned "$prog" "$spawns"; then
      fail "$prog: not restarted within 30 s of kill -9"; continue
    fi
    new_pid=$(pid_of "$prog")
    t_spawn=$(spawn_time_us "$prog")
    [ "$new_pid" != "${before_pid[$prog]}" ] || fail "$prog: same pid after the restart"
    restart_ms=$(( (t_spawn - t_kill) / 1000 ))
    # Evidence that the pipeline works again, received after the restart.
    case "$prog" in
      wingman-camera-driver) evidence() { awk -v w="$t_spawn" '$2 == "IMAGE" && $3 == "IMAGE_SUPCAM" && $1 >= w {print $1; exit}' "$bus"; }
                             what="first image" ;;
      wingman-follower-ctrl) evidence() { awk -v w="$t_spawn" '$2 == "SETPOINT" && $1 >= w {print $1; exit}' "$bus"; }
                             what="first setpoint" ;;
      *) evidence() { first_fresh_target_wall "$last_det_utime" "$t_spawn"; }
         what="first fresh target" ;;
    esac
    if wait_for 60 has_evidence; then
      back_ms=$(( ($(evidence) - t_spawn) / 1000 ))
      awk -v ms="$back_ms" -v b="$bound_s" 'BEGIN {exit !(ms <= 1000 * b)}' ||
        fail "$prog: $what $back_ms ms after the restart (bound $bound_s s)"
      if [ "$back_ms" -le $((target_s * 1000)) ]; then met="within"; else met="NOT within"; fi
    else
      back_ms="none" met="NOT within"; fail "$prog: no $what within 60 s of the restart"
    fi
    # Nobody else crashed: same pids, no other exit logged.
    for p in "${programs[@]}"; do
      [ "$p" = "$prog" ] && continue
      if [ "$(pid_of "$p")" != "${before_pid[$p]}" ] || ! kill -0 "${before_pid[$p]}" 2>/dev/null; then
        fail "$prog killed: $p restarted too (pid ${before_pid[$p]} -> $(pid_of "$p"))"
      fi
      [ "$(exits_of "$p")" = "${before_exits[$p]}" ] || fail "$prog killed: supervisord logged an exit of $p"
    done
    line="$prog: restarted $restart_ms ms after kill -9 (pid ${before_pid[$prog]} -> $new_pid), $what $back_ms ms"
    line+=" after the restart ($met the ${target_s} s target)"
    if [ "$prog" = wingman-localizer ] && [ "$back_ms" != none ]; then
      # Message time: setpoints after the last targets before the kill (plus the hold timeout) and before the first
      # fresh target after the restart must all be holds.
      first_back_utime=$(fresh_targets "$last_det_utime" "$t_spawn" | head -n 1 | awk '{print $3}')
      read -r n_sp n_hold <<< "$(awk -v a="$last_targets_utime" -v t="$hold_timeout_s" -v b="$first_back_utime" \
        '$2 == "SETPOINT" && $3 > a + t * 1e6 && $3 < b {n++; if ($4 == 0) h++} END {print n + 0, h + 0}' "$bus")"
      gap_s=$(awk -v a="$last_targets_utime" -v b="$first_back_utime" 'BEGIN {printf "%.2f", (b - a) / 1e6}')
      [ "$n_sp" = "$n_hold" ] || fail "localizer down: $((n_sp - n_hold)) of $n_sp setpoints were not holds"
      line+="; targets gap $gap_s s of message time, $n_hold of $n_sp setpoints after hold.timeout_s were holds"
      # The gap must be longer than the hold timeout for the hold check to have checked anything.
      awk -v g="$gap_s" -v t="$hold_timeout_s" 'BEGIN {exit !(g > t + 0.1)}' && [ "$n_sp" -eq 0 ] &&
        fail "localizer down for $gap_s s of message time but no setpoint in the gap"
    fi
    if [ "$prog" = wingman-detector ]; then
      # Health in the heartbeat: while the detector was down the localizer's input went stale (docs: StatusTracker).
      stale=$(awk -v a="$t_kill" '$2 == "STATUS" && $3 == "STATUS_LOCALIZER" && $1 >= a && $5 == 2 && /DETECTIONS_CAM0/ {
                $1 = $2 = $3 = $4 = $5 = ""; sub(/^ +/, ""); print; exit}' "$bus")
      line+="; localizer heartbeat meanwhile: ${stale:-no DEGRADED heartbeat naming DETECTIONS_CAM0}"
    fi
    echo "supervisor_fault_test: $line"
    summary+=("$line")
  done
done

kill -0 "$sim_pid" 2>/dev/null || fail "wingman-sim exited during the test: $(tail -n 3 "$tmp/sim.txt")"
# A clean stop: SIGTERM to supervisord stops every program (each exits 0 within 1 s).
stop_pid "$sim_pid"; sim_pid=""
stop_pid "$sup_pid"; sup_pid=""
for p in "${programs[@]}"; do
  grep -q "stopped: $p (exit status 0)" "$suplog" || fail "$p: no clean stop (exit 0) on SIGTERM: $(grep "$p" "$suplog" | tail -n 2)"
done

echo
echo "supervisor_fault_test: figures (sync.speed $speed, 640x360 renders, shipped CNN, bound $bound_s s," \
     "load average $(cut -d ' ' -f 1-3 /proc/loadavg)):"
echo "  detection rate $det_rate % ($with_box of $frames frames in 10 s)"
for line in "${summary[@]}"; do echo "  $line"; done
if [ "$failures" -gt 0 ]; then echo "supervisor_fault_test: $failures failure(s)"; WINGMAN_FAULT_KEEP=1; exit 1; fi
echo "supervisor_fault_test: passed"

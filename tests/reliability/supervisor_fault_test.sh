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
# Then (issue 33, "the supervised flight survives, in one test run") the same flight goes on through, in order:
#  - SIGSTOP of the localizer: supervisord only sees exits and the process's own --watchdog thread is stopped with
#    it; the shipped stopped-process listener (config/supervisor/wingman-stopped-watch.py) must kill it, supervisord
#    restart it;
#  - the hang-inducing message: a copy of a real image whose seq jumps by 10^7 (wingman-bus-inject, a test tool):
#    the detector must count the 9,999,999 missing frames in one step and stay up;
#  - a copy of a real message dated 1 h ahead on each input (IMAGE_CAM0, DETECTIONS_CAM0, OWN_POSE, TARGETS): it
#    must be dropped and counted (heartbeat) by the stage that keeps the time, and nothing dated in the future may
#    follow it (targets, setpoints);
#  - a corrupt log (the recorder's recording of this flight, one event's length made 2^31-1) fed to a replay
#    (`wingman replay`, on a bus of its own, and a localizer file to file): exit 1 naming the byte offset;
#    `--skip-corrupt` plays on (exit 0).
#  After each: no other supervised process restarted; a target from a new image within WINGMAN_SURVIVE_BOUND_S
#  (default 3 s, the issue's figure, asserted; wall time from the restart, the injection or the replay's end); every
#  setpoint with no real target within hold.timeout_s before it (from the newest targets before the fault to that
#  first fresh target) is a MODE_HOLD; the follower flies again (a velocity setpoint).
#
# Usage: tests/reliability/supervisor_fault_test.sh SRC_DIR BIN_DIR TESTS_BIN_DIR
# Environment (for runs by hand): WINGMAN_FAULT_SPEED (sync.speed, default 0.5), WINGMAN_FAULT_ROUNDS (kill rounds
# over the four processes, default 1), WINGMAN_FAULT_BOUND_S (restart bound, default 20), WINGMAN_FAULT_KEEP=1 keeps
# the temporary folder (logs, rendered configs, bus trace), WINGMAN_SURVIVE_BOUND_S (the survival bound, default 3).
# Exits 77 (skipped) without supervisord.
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
for exe in wingman-bus-watch wingman-bus-inject; do
  [ -x "$tbin/$exe" ] || { echo "supervisor_fault_test: $tbin/$exe is missing" >&2; exit 2; }
done

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
# (The log folder stands for both the recorder's directory, /var/log/wingman/, and supervisord's, /var/log/supervisor/.)
if ! diff <(sed -e "s|$bin/|/usr/local/bin/|g" -e "s|$etc/|/usr/local/etc/wingman/|g" \
               -e "s|^directory=$tmp/sup/log/|directory=/var/log/wingman/|" \
               -e "s|$tmp/sup/log/recordings|/var/log/wingman/recordings|g" -e "s|$tmp/sup/log/|/var/log/supervisor/|g" \
               -e "s|$src/config/supervisor/|/usr/local/share/wingman/supervisor/|g" \
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
  for p in "${programs[@]}" wingman-stopped-watch; do
    grep -q "success: $p entered RUNNING" "$suplog" 2>/dev/null || return 1
  done
}

# --- Start: the bus watcher, supervisord, the simulated flight ---
bus="$tmp/bus.txt"
"$tbin/wingman-bus-watch" --lcm-url "$url" --image IMAGE_SUPCAM --seconds 590 > "$bus" 2> "$tmp/bus.err" &
watch_pid=$!
supervisord -n -c "$conf" > "$tmp/sup/stdout.txt" 2>&1 &
sup_pid=$!
wait_for 60 all_running ||
  { fail "the four programs and the stopped-process listener did not reach RUNNING within 60 s"; cat "$suplog"; exit 1; }
echo "supervisor_fault_test: supervisord runs the four programs and the stopped-process listener" \
     "(config rendered from config/supervisor/wingman.conf)"

cat > "$tmp/sim.yaml" <<YAML
scenario: {file: "$src/tests/reliability/hover_close.yaml"}
camera: {width: 640, height: 360, focal_px: 320.0, rate_hz: 30.0}
sync: {mode: realtime, speed: $speed, wait_for: [detector, localizer, follower_ctrl], startup_timeout_s: 120.0}
render: {enabled: true, supersampling: 1}
YAML
"$bin/wingman-sim" --lcm-url "$url" --config "$tmp/sim.yaml" --log-level warn > "$tmp/sim.txt" 2>&1 &
sim_pid=$!

# Message times at or above lie_floor are the survival phase's future-dated copies (set at the first one), never data.
lie_floor=9000000000000000000
# TARGETS lines with a target whose newest image is newer than $1 (message time), received at or after $2 (wall us).
# (The first one is taken by awk's exit, not by head: with pipefail, head closing the pipe early fails the pipeline.)
fresh_targets() { awk -v s="$1" -v w="$2" -v f="$lie_floor" '$2 == "TARGETS" && $4 > 0 && $5 > s && $5 < f && $1 >= w' "$bus"; }
first_fresh_target() {
  awk -v s="$1" -v w="$2" -v f="$lie_floor" '$2 == "TARGETS" && $4 > 0 && $5 > s && $5 < f && $1 >= w {print; exit}' "$bus"
}
first_fresh_target_wall() { first_fresh_target "$1" "$2" | awk '{print $1}'; }
# setpoint_holds A B: the setpoints dated after A and before B (message time), in bus order, split by the follower's
# own rule: "stale" when no real targets message with a target, dated at most hold.timeout_s before the setpoint, was
# on the bus before it; prints <stale> <stale that were holds> <answering a target within hold.timeout_s>. Every
# stale setpoint must be a hold: that is "no flying on old data". (Checking every setpoint after A + hold.timeout_s
# instead would count a target that arrived between reading A and the fault, racing the reader.)
setpoint_holds() {
  awk -v a="$1" -v b="$2" -v t="$hold_timeout_s" -v f="$lie_floor" '
    $2 == "TARGETS" && $4 > 0 && $3 < f && $3 > newest {newest = $3}
    $2 == "SETPOINT" && $3 > a && $3 < b {if (newest >= $3 - t * 1e6) ok++; else {n++; if ($4 == 0) h++}}
    END {print n + 0, h + 0, ok + 0}' "$bus"
}
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
      if [ "$back_ms" -le 3000 ]; then met3="within"; else met3="NOT within"; fi
    else
      back_ms="none" met="NOT within" met3="NOT within"; fail "$prog: no $what within 60 s of the restart"
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
    line+=" after the restart ($met the ${target_s} s target, $met3 3 s)"
    if [ "$prog" = wingman-localizer ] && [ "$back_ms" != none ]; then
      # Message time: setpoints after the last targets before the kill (plus the hold timeout) and before the first
      # fresh target after the restart must all be holds.
      first_back_utime=$(first_fresh_target "$last_det_utime" "$t_spawn" | awk '{print $3}')
      read -r n_sp n_hold n_ok <<< "$(setpoint_holds "$last_targets_utime" "$first_back_utime")"
      gap_s=$(awk -v a="$last_targets_utime" -v b="$first_back_utime" 'BEGIN {printf "%.2f", (b - a) / 1e6}')
      [ "$n_sp" = "$n_hold" ] || fail "localizer down: $((n_sp - n_hold)) of $n_sp setpoints were not holds"
      line+="; targets gap $gap_s s of message time, $n_hold of $n_sp setpoints after hold.timeout_s were holds"
      line+=" ($n_ok answered a target within it)"
      # The gap must be longer than the hold timeout for the hold check to have checked anything.
      awk -v g="$gap_s" -v t="$hold_timeout_s" 'BEGIN {exit !(g > t + 0.1)}' && [ "$n_sp" -eq 0 ] &&
        fail "localizer down for $gap_s s of message time but no setpoint in the gap"
    fi
    if [ "$prog" = wingman-detector ]; then
      # Health in the heartbeat: while the detector was down the localizer's input went stale (docs: StatusTracker).
      stale=$(awk -v a="$t_kill" '$2 == "STATUS" && $3 == "STATUS_LOCALIZER" && $1 >= a && $5 == 2 && /DETECTIONS_CAM0/ {
                $1 = $2 = $3 = $4 = $5 = $6 = ""; sub(/^ +/, ""); print; exit}' "$bus")
      line+="; localizer heartbeat meanwhile: ${stale:-no DEGRADED heartbeat naming DETECTIONS_CAM0}"
    fi
    echo "supervisor_fault_test: $line"
    summary+=("$line")
  done
done

# --- Issue 33: the same flight goes on through SIGSTOP, a hang-inducing message, a future-dated message on each
# input and a corrupt log fed to a replay. After each: a fresh target within the survival bound (the issue's 3 s;
# wall time from the restart for SIGSTOP, from the injection for a message, from the replay's end for the log), no
# other supervised process restarted, and every setpoint between the newest targets before the fault (plus
# hold.timeout_s) and that first fresh target is a MODE_HOLD (message time).
t_survival=$SECONDS
declare -A before_pid=() before_exits=()
snapshot() {
  local p
  for p in "${programs[@]}"; do before_pid[$p]=$(pid_of "$p"); before_exits[$p]=$(exits_of "$p"); done
}
# others_unchanged EXCEPT WHAT: every supervised program but EXCEPT kept its pid and had no exit logged.
others_unchanged() {
  local p
  for p in "${programs[@]}"; do
    [ "$p" = "$1" ] && continue
    if [ "$(pid_of "$p")" != "${before_pid[$p]}" ] || ! kill -0 "${before_pid[$p]}" 2>/dev/null; then
      fail "$2: $p restarted (pid ${before_pid[$p]} -> $(pid_of "$p"))"
    fi
    [ "$(exits_of "$p")" = "${before_exits[$p]}" ] || fail "$2: supervisord logged an exit of $p"
  done
}
# The newest real message times on the bus (the future-dated copies left out).
newest_det_utime() { awk -v f="$lie_floor" '$2 == "DETECTIONS" && $4 < f {u = $4} END {printf "%.0f\n", u}' "$bus"; }
newest_targets_utime() { awk -v f="$lie_floor" '$2 == "TARGETS" && $3 < f {u = $3} END {printf "%.0f\n", u}' "$bus"; }
# The newest drops count a heartbeat on status channel $1 reported for its input $2 (0 if none yet).
input_drops() { awk -v s="$1" -v c="$2" '$2 == "INPUT" && $3 == s && $5 == c {d = $7} END {print d + 0}' "$bus"; }
# Wall time (us) of the first heartbeat on $1 received at or after $3 whose input $2 has more than $4 drops.
drop_seen_wall() {
  awk -v s="$1" -v c="$2" -v w="$3" -v d="$4" '$2 == "INPUT" && $3 == s && $5 == c && $1 >= w && $7 > d {print $1; exit}' "$bus"
}
has_drop_seen() { [ -n "$(drop_seen_wall "$@")" ]; }
# The first last_error on $1 received at or after $2 that matches $3.
last_error_after() {
  awk -v s="$1" -v w="$2" -v m="$3" '$2 == "LASTERR" && $3 == s && $1 >= w && index($0, m) {
    $1 = $2 = $3 = $4 = ""; sub(/^ +/, ""); print; exit}' "$bus"
}
survive_s="${WINGMAN_SURVIVE_BOUND_S:-3}"
# after_fault NAME FROM_WALL_US DET_UTIME TARGETS_UTIME [NOTE]: waits for the first target from an image newer than
# DET_UTIME received after FROM_WALL_US, checks the bound and the holds since TARGETS_UTIME, adds the figures' line.
after_fault() {
  local name="$1" from="$2" s="$3" a="$4" note="${5:-}" back_ms met b n_sp n_hold gap_s line
  if wait_for 30 has_fresh_target "$s" "$from"; then
    back_ms=$(( ($(first_fresh_target_wall "$s" "$from") - from) / 1000 ))
    if [ "$back_ms" -le $((survive_s * 1000)) ]; then met="within"; else
      met="NOT within"; fail "$name: first fresh target $back_ms ms after (bound $survive_s s)"
    fi
    b=$(first_fresh_target "$s" "$from" | awk '{print $3}')
    read -r n_sp n_hold n_ok <<< "$(setpoint_holds "$a" "$b")"
    gap_s=$(awk -v a="$a" -v b="$b" 'BEGIN {printf "%.2f", (b - a) / 1e6}')
    [ "$n_sp" = "$n_hold" ] ||
      fail "$name: $((n_sp - n_hold)) of $n_sp setpoints without a target within hold.timeout_s were not holds"
    # The follower flies again (a latched follower would hold or stay silent): a velocity setpoint after the fault.
    flying() { awk -v w="$from" -v f="$lie_floor" '$2 == "SETPOINT" && $1 >= w && $3 < f && $4 == 2 {print $1; exit}' "$bus"; }
    is_flying() { [ -n "$(flying)" ]; }
    if wait_for 10 is_flying; then fly_ms=$(( ($(flying) - from) / 1000 )); else
      fly_ms="none"; fail "$name: the follower published no velocity setpoint within 10 s"
    fi
    line="$name: first fresh target $back_ms ms after ($met ${survive_s} s); in the $gap_s s of message time from the"
    line+=" newest targets before it to that one,"
    line+=" $n_hold of $n_sp setpoints without a target within hold.timeout_s were holds ($n_ok answered one),"
    line+=" first velocity setpoint $fly_ms ms after"
  else
    fail "$name: no fresh target within 30 s"; line="$name: no fresh target within 30 s"
  fi
  [ -z "$note" ] || line+="; $note"
  echo "supervisor_fault_test: $line"
  summary+=("$line")
}
steady_or_die() { wait_for 60 targets_steady || { fail "$1: no steady targets before it"; exit 1; }; }

# 1. SIGSTOP of the localizer: supervisord sees exits only and the process's own watchdog thread is stopped with it;
#    the shipped listener (config/supervisor/wingman-stopped-watch.py) kills it after 5-10 s, autorestart restarts it.
prog=wingman-localizer
steady_or_die "SIGSTOP"
snapshot
spawns=$(spawns_of "$prog") stop_pid_=${before_pid[$prog]} s=$(newest_det_utime) a=$(newest_targets_utime)
t_stop=$(now_us)
kill -STOP "$stop_pid_"
if wait_for 25 respawned "$prog" "$spawns"; then
  t_spawn=$(spawn_time_us "$prog")
  exit_line=$(grep "exited: $prog " "$suplog" | tail -n 1)
  t_exit=$(( $(date -d "$(echo "$exit_line" | awk '{print $1" "$2}' | tr ',' '.')" +%s%3N) * 1000 ))
  grep -q "$prog (pid $stop_pid_) is stopped" "$tmp/sup/log/wingman-stopped-watch.log" ||
    fail "SIGSTOP $prog: the stopped-process listener logged no kill of pid $stop_pid_"
  after_fault "SIGSTOP $prog (pid $stop_pid_)" "$t_spawn" "$s" "$a" \
    "killed by the listener $(( (t_exit - t_stop) / 1000 )) ms after SIGSTOP (supervisord: '${exit_line#*exited: }'), restarted $(( (t_spawn - t_stop) / 1000 )) ms after SIGSTOP (pid $(pid_of "$prog"))"
else
  fail "SIGSTOP $prog: not restarted within 25 s (supervisord does not see a stopped process)"
  kill -CONT "$stop_pid_" 2>/dev/null || true
fi
others_unchanged "$prog" "SIGSTOP $prog"

# 2. The hang-inducing message: a copy of a real frame whose seq jumps by 10^7 (the detector once logged each
#    "missing" frame; at 2^62 it never came back). It must be counted in one step, the detector staying up.
steady_or_die "seq jump"
snapshot
s=$(newest_det_utime) a=$(newest_targets_utime)
det_drops0=$(awk '$2 == "STATUS" && $3 == "STATUS_DETECTOR" {d = $6} END {print d + 0}' "$bus")
out=$("$tbin/wingman-bus-inject" --lcm-url "$url" --channel IMAGE_CAM0 --type image --seq-jump 10000000 --timeout 10) ||
  { fail "seq jump: the injector failed"; exit 1; }
read -r t_inj _ _ _ _ _ inj_seq <<< "$out"
jump_counted() {
  awk -v w="$t_inj" -v d="$det_drops0" '$2 == "STATUS" && $3 == "STATUS_DETECTOR" && $1 >= w && $6 >= d + 9999999 {
    print $1; exit}' "$bus"
}
has_jump_counted() { [ -n "$(jump_counted)" ]; }
if wait_for 5 has_jump_counted; then
  note="counted in the detector's heartbeat $(( ($(jump_counted) - t_inj) / 1000 )) ms after"
  err=$(last_error_after STATUS_DETECTOR "$((t_inj - 1000000))" "before seq $inj_seq")
  note+=" (last_error: ${err:-overwritten by a later drop before the heartbeat})"
else
  fail "seq jump: no detector heartbeat counting the 9,999,999 missing frames within 5 s"; note="not counted"
fi
after_fault "image seq +10^7 to the detector" "$t_inj" "$s" "$a" "$note"
others_unchanged "" "seq jump"

# 3. A copy of a real message dated 1 h ahead on each input: dropped and counted by the stage that reads it (the
#    detector keeps a clock of image times: a future frame is dropped before detection), never adopted as the
#    clock, never passed on (no detections, targets or setpoints dated in the future).
for spec in "IMAGE_CAM0 image STATUS_DETECTOR:IMAGE_CAM0" \
            "DETECTIONS_CAM0 detections STATUS_LOCALIZER:DETECTIONS_CAM0" \
            "OWN_POSE own_pose STATUS_LOCALIZER:OWN_POSE STATUS_FOLLOWER_CTRL:OWN_POSE" \
            "TARGETS targets STATUS_FOLLOWER_CTRL:TARGETS"; do
  read -r ch type counters <<< "$spec"
  name="$ch dated +3600 s"
  steady_or_die "$name"
  snapshot
  s=$(newest_det_utime) a=$(newest_targets_utime)
  declare -A drops0=()
  for c in $counters; do drops0[$c]=$(input_drops "${c%%:*}" "${c#*:}"); done
  t_inj=""
  if out=$("$tbin/wingman-bus-inject" --lcm-url "$url" --channel "$ch" --type "$type" --ahead-s 3600 --timeout 10); then
    read -r t_inj _ _ _ orig_utime lie_utime _ <<< "$out"
    # Everything dated at least 30 min after the first lie's original time is a lie (the flight lasts minutes).
    [ "$lie_floor" != 9000000000000000000 ] || lie_floor=$((orig_utime + 1800000000))
  else
    fail "$name: the injector failed"
  fi
  [ -n "$t_inj" ] || continue
  note="counted:"
  for c in $counters; do
    if wait_for 5 has_drop_seen "${c%%:*}" "${c#*:}" "$t_inj" "${drops0[$c]}"; then
      note+=" ${c%%:*} drops on ${c#*:} in $(( ($(drop_seen_wall "${c%%:*}" "${c#*:}" "$t_inj" "${drops0[$c]}") - t_inj) / 1000 )) ms"
      err=$(last_error_after "${c%%:*}" "$t_inj" "max_ahead_s")
      [ -z "$err" ] || note+=" ('$err')"
    else
      fail "$name: ${c%%:*} did not count a drop on ${c#*:} within 5 s"; note+=" ${c%%:*} NOTHING on ${c#*:}"
    fi
  done
  if [ "$ch" = IMAGE_CAM0 ]; then
    n_det=$(awk -v w="$((t_inj - 1000000))" -v f="$lie_floor" '$2 == "DETECTIONS" && $1 >= w && $4 >= f' "$bus" | wc -l)
    [ "$n_det" -eq 0 ] || fail "$name: the detector passed the lie on as $n_det detections message(s) dated +3600 s"
  fi
  after_fault "$name" "$t_inj" "$s" "$a" "$note"
  # The lie went no further: no targets or setpoints dated in the future after it (the TARGETS lie itself aside;
  # the bus watcher can receive a copy before the injector has printed its time, hence the second's margin).
  n_lies=$(awk -v w="$((t_inj - 1000000))" -v f="$lie_floor" -v l="$lie_utime" -v c="$ch" \
    '($2 == "TARGETS" || $2 == "SETPOINT") && $1 >= w && $3 >= f && !($2 == c && $3 == l)' "$bus" | wc -l)
  [ "$n_lies" -eq 0 ] || fail "$name: $n_lies targets or setpoint message(s) dated in the future followed"
  others_unchanged "" "$name"
done

# 4. A corrupt log fed to a replay, beside the flight: the recorder's own recording of this flight, cut to its first
#    events, one event's data length made 2^31-1. `wingman replay` (publishing on a bus of its own, not the
#    flight's) and a localizer replaying it file to file must stop with exit 1 naming the byte offset; with
#    --skip-corrupt the replay plays the rest (exit 0).
steady_or_die "corrupt log"
snapshot
s=$(newest_det_utime) a=$(newest_targets_utime)
rec=$(ls -t "$tmp/sup/log/recordings/"*.lcmlog 2>/dev/null | head -n 1 || true)
if [ -z "$rec" ]; then
  fail "corrupt log: the recorder wrote no recording"
else
  read -r offset n_events <<< "$(python3 - "$rec" "$tmp/corrupt.lcmlog" <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
events, at = [], 0
while at + 28 <= len(data) and len(events) < 400:
    sync, _, _, chan_len, data_len = struct.unpack(">IqqII", data[at:at + 28])
    end = at + 28 + chan_len + data_len
    if sync != 0xEDA1DA01 or end > len(data):
        break
    events.append((at, end))
    at = end
bad = len(events) // 2
out = bytearray(data[:events[-1][1]])
out[events[bad][0] + 24:events[bad][0] + 28] = struct.pack(">I", 0x7FFFFFFF)
open(sys.argv[2], "wb").write(out)
print(events[bad][0], len(events))
PY
)"
  replay_url="udpm://239.255.76.68:7669?ttl=0"
  t_log=$(now_us) rc=0
  timeout 60 "$bin/wingman" replay "$tmp/corrupt.lcmlog" --lcm-url "$replay_url" --speed 0 > "$tmp/replay.txt" 2>&1 || rc=$?
  replay_line=$(grep -m 1 "byte $offset" "$tmp/replay.txt" || true)
  [ "$rc" = 1 ] && [ -n "$replay_line" ] ||
    fail "corrupt log: wingman replay exited $rc, not 1 with a line naming byte $offset: $(tail -n 2 "$tmp/replay.txt")"
  rc_skip=0
  timeout 60 "$bin/wingman" replay "$tmp/corrupt.lcmlog" --lcm-url "$replay_url" --speed 0 --skip-corrupt \
    > "$tmp/replay_skip.txt" 2>&1 || rc_skip=$?
  [ "$rc_skip" = 0 ] || fail "corrupt log: wingman replay --skip-corrupt exited $rc_skip: $(tail -n 2 "$tmp/replay_skip.txt")"
  rc_loc=0
  timeout 60 "$bin/wingman-localizer" --name replay_localizer --lcm-url "$replay_url" --log-level warn \
    --lcm-in "file://$tmp/corrupt.lcmlog?speed=0" --lcm-out "file://$tmp/replayed.lcmlog?mode=w" \
    > "$tmp/replay_localizer.txt" 2>&1 || rc_loc=$?
  loc_line=$(grep -m 1 "byte $offset" "$tmp/replay_localizer.txt" || true)
  [ "$rc_loc" = 1 ] && [ -n "$loc_line" ] ||
    fail "corrupt log: wingman-localizer exited $rc_loc, not 1 naming byte $offset: $(tail -n 2 "$tmp/replay_localizer.txt")"
  t_end=$(now_us)
  after_fault "corrupt log ($n_events events of the flight's recording, bad one at byte $offset) fed to a replay" \
    "$t_end" "$s" "$a" "wingman replay exit $rc ('$replay_line'), with --skip-corrupt exit $rc_skip, localizer file to file exit $rc_loc; the three took $(( (t_end - t_log) / 1000 )) ms"
fi
others_unchanged "" "corrupt log"

t_survival=$((SECONDS - t_survival))
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
echo "  detection rate $det_rate % ($with_box of $frames frames in 10 s); the test took $SECONDS s, the issue-33 faults" \
     "(SIGSTOP onwards) $t_survival s of it"
for line in "${summary[@]}"; do echo "  $line"; done
if [ "$failures" -gt 0 ]; then echo "supervisor_fault_test: $failures failure(s)"; WINGMAN_FAULT_KEEP=1; exit 1; fi
echo "supervisor_fault_test: passed"

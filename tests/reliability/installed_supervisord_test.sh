#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Install anywhere, supervised (issue 34, deliverable 1, "Done when"): for each of the prefixes /usr and /opt/wingman,
# on a "fresh machine" made without touching the host, installs the build for real (`cmake --install BUILD --prefix
# P`, no DESTDIR), starts the installed stack under Debian's supervisord as the installed file says (its rendered
# share/wingman/supervisor/wingman.conf copied to /etc/supervisor/conf.d/, then `supervisord -c
# /etc/supervisor/supervisord.conf`), checks it is up, flies one short simulated flight through it, and checks that
# both prefixes give the same figures.
#
# The fresh machine: each prefix runs in a namespace of its own (unshare: mount, network and pid namespaces; the pid
# namespace's init is this script, so every process it started dies with it, and the mounts die with the namespace):
#   /usr, /etc, /var  overlayfs over the host's (the writes go to a tmpfs; the host's files are the lower layer)
#   /opt, /run        an empty tmpfs (supervisord's socket and pid file are in /run)
#   network           loopback only, multicast routed to it: the LCM bus never reaches the host's network
# Per prefix it checks:
#   - supervisorctl status: the six programs of group wingman and the listener wingman-stopped-watch RUNNING;
#   - a heartbeat (STATUS_<NAME>) of each of the six processes on the bus, from the pid supervisord reports, read
#     with the INSTALLED Python types (P/lib/python3/dist-packages; for /usr Debian's python3 finds them unaided);
#   - the flight: wingman-sim stands in for the camera and the autopilot (it renders IMAGE_CAM0 and publishes
#     OWN_POSE, takes SETPOINT; the MAVLink bridge waits for an autopilot that does not come). There is no
#     /dev/video0 here (the installed camera driver would wait for it, heartbeat ERROR), so the installed
#     camera_driver.yaml is edited as a vehicle owner would: a looped clip
#     on a channel of its own (IMAGE_SUPCAM), the rest at the shipped values. Lockstep, the README's formation
#     (config/scenarios/formation_2d.yaml, the shipped CNN on rendered images) for WINGMAN_SUPD_DURATION s (default
#     12), recorded with lcm-logger and evaluated with the installed `wingman eval` and the installed follower
#     configuration;
#   - no program restarted during the flight (same pids), the recorder wrote a recording in the installed folder,
#     and SIGTERM to supervisord stops every program with exit status 0.
# Then: each flight is within installed_flight's bounds (localization RMS <= 0.45 m, formation RMS <= 0.60 m,
# estimates in >= 90 % of the frames with the leader visible, one id, no false target). When both detectors ran the
# same backend (their heartbeats say which: "auto" times OpenCL against OpenCV's CPU path at start, so under load the
# two installs may choose differently), both flights' eval.json are equal, the fields with latency in their names
# (wall-clock) and the detectors' backend lines aside, and their targets.csv equal byte for byte; otherwise their
# localization RMS agree within 0.05 m, their formation RMS within 0.15 m and their frame counts within 2 % (the two
# backends, each pinned, flew this 12-s flight 0.022 m and 0.073 m apart).
# The host's /usr/bin/wingman-detector, /etc/wingman, /opt/wingman, /etc/opt/wingman and /var/log/wingman are
# checked unchanged (present or absent as before).
#
# Usage: tests/reliability/installed_supervisord_test.sh SRC_DIR BUILD_DIR [WORK_DIR]
# Environment: WINGMAN_SUPD_DURATION (flight seconds, default 12), WINGMAN_SUPD_KEEP=1 keeps the work folder.
# Exits 77 (skipped) without root, unshare, overlayfs or supervisord.
set -euo pipefail
src=$(cd "$1" && pwd) build=$(cd "$2" && pwd)
me="installed_supervisord"
programs=(wingman-recorder wingman-camera-driver wingman-detector wingman-localizer wingman-follower-ctrl wingman-mavlink)

if [ "${WINGMAN_SUPD_INNER:-}" = 1 ]; then
  # ---------------------------------------------------------------- one prefix, inside its namespaces (pid 1) ---
  prefix="$3" out="$4" duration="$5"
  say() { echo "$me [$prefix]: $*"; }
  die() { echo "$me [$prefix]: FAIL: $*" >&2; exit 1; }
  skip() { echo "$me [$prefix]: SKIPPED: $*"; exit 77; }
  if ! { ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo; }; then
    skip "cannot set up the private network namespace's loopback for multicast"
  fi
  # The fresh machine: overlays and tmpfs, all in this mount namespace only.
  ns="$out/ns"
  mkdir -p "$ns"
  mount -t tmpfs wingman-supd "$ns" || skip "cannot mount a tmpfs in a private mount namespace"
  for d in usr etc var; do
    mkdir -p "$ns/$d.upper" "$ns/$d.work"
    mount -t overlay "wingman-$d" -o "lowerdir=/$d,upperdir=$ns/$d.upper,workdir=$ns/$d.work" "/$d" ||
      skip "cannot mount an overlayfs over /$d"
  done
  mount -t tmpfs wingman-opt /opt || skip "cannot mount a tmpfs over /opt"
  mount -t tmpfs wingman-run /run || skip "cannot mount a tmpfs over /run"

  sup_pid="" logger_pid="" sim_pid=""
  ctl() { timeout 20 supervisorctl -c /etc/supervisor/supervisord.conf "$@"; }
  stop_pid() {  # stop_pid PID: SIGTERM, then SIGKILL after 10 s
    local pid="$1" _
    [ -n "$pid" ] || return 0
    kill -TERM "$pid" 2>/dev/null || return 0
    for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
  }
  # shellcheck disable=SC2317  # the EXIT trap calls it
  cleanup() {
    stop_pid "$sim_pid"; stop_pid "$logger_pid"; stop_pid "$sup_pid"
    cp /var/log/supervisor/*.log "$out/" 2>/dev/null || true
  }
  trap cleanup EXIT

  # 1. Install, as on a vehicle: the build for the prefix, the program file into supervisord's conf.d.
  case "$prefix" in /usr) confdir=/etc/wingman recdir=/var/log/wingman/recordings ;;
                    /opt/*) confdir="/etc$prefix/wingman" recdir="/var$prefix/log/wingman/recordings" ;;
                    *) die "this test knows the layouts of /usr and /opt/NAME only" ;; esac
  [ ! -e "$prefix/bin/wingman-detector" ] ||
    skip "not a fresh machine: the host has $prefix/bin/wingman-detector installed already"
  cmake --install "$build" --prefix "$prefix" > "$out/install.log" 2>&1 || { cat "$out/install.log" >&2; die "cmake --install"; }
  bin="$prefix/bin"
  conf="$prefix/share/wingman/supervisor/wingman.conf"
  [ -r "$conf" ] || die "$conf was not installed"
  [ -d /var/log/supervisor ] || die "/var/log/supervisor is missing (Debian's supervisor package makes it)"
  cp "$conf" /etc/supervisor/conf.d/wingman.conf
  # The one edit a machine without the camera needs: the installed camera driver opens /dev/video0 at start and
  # exits 1 when it is missing (by design; supervisord would restart it every 1-4 s). Edited as a vehicle owner
  # edits the installed file: the driver plays a looped clip on a channel of its own (IMAGE_SUPCAM) and the
  # simulator renders IMAGE_CAM0, the detector's input; every other key stays at the shipped value (the defaults).
  "$prefix/bin/wingman" make-video --frames 60 --width 320 --height 240 --fps 10 "$out/clip.avi" > /dev/null 2>&1 ||
    die "wingman make-video"
  cp "$confdir/camera_driver.yaml" "$out/camera_driver.shipped.yaml"
  cat > "$confdir/camera_driver.yaml" <<YAML
# The shipped file with the camera's source and channel edited (tests/reliability/installed_supervisord_test.sh).
source: {kind: file}
file: {path: "$out/clip.avi", mode: realtime, fps: 10, loop: true}
output: {channel: IMAGE_SUPCAM, camera_id: 1}
YAML
  url=$(grep -m 1 -o 'WINGMAN_LCM_URL="[^"]*"' "$conf" | cut -d '"' -f 2)
  [ -n "$url" ] || die "no WINGMAN_LCM_URL in $conf"
  say "installed (configurations in $confdir); the bus of the installed file: $url"

  # 2. supervisord as Debian runs it, with its own main configuration.
  SECONDS=0
  supervisord -n -c /etc/supervisor/supervisord.conf > "$out/supervisord.stdout" 2>&1 &
  sup_pid=$!
  all_running() {
    local st p
    st=$(ctl status 2>/dev/null || true)
    for p in "${programs[@]}"; do grep -qE "^wingman:$p +RUNNING" <<< "$st" || return 1; done
    grep -qE '^wingman-stopped-watch +RUNNING' <<< "$st"
  }
  for _ in $(seq 1 120); do all_running && break; sleep 0.5; done
  ctl status > "$out/status_before.txt" 2>&1 || true
  all_running || { cat "$out/status_before.txt" >&2; tail -n 20 /var/log/supervisor/supervisord.log >&2;
                   die "not every program RUNNING within 60 s"; }
  up_s=$SECONDS
  declare -A pid_before=()
  for p in "${programs[@]}"; do pid_before[$p]=$(ctl pid "wingman:$p"); done
  say "supervisord runs the six programs and the listener (RUNNING after $up_s s)"

  # 3. A heartbeat from each, from the pid supervisord reports, read with the installed Python types.
  pypath="$prefix/lib/python3/dist-packages"
  pyenv=(env "PYTHONPATH=$pypath")
  [ "$prefix" != /usr ] || pyenv=(env -u PYTHONPATH)  # Debian's python3 searches /usr/lib/python3/dist-packages
  expected=""
  for p in "${programs[@]}"; do expected+="${p} ${pid_before[$p]} "; done
  if ! "${pyenv[@]}" /usr/bin/python3 - "$url" "$expected" > "$out/heartbeats.txt" 2>&1 <<'PY'
import sys
import wingman
from wingman_lcm import Udpm

program = {"recorder": "wingman-recorder", "camera_driver": "wingman-camera-driver", "detector": "wingman-detector",
           "localizer": "wingman-localizer", "follower_ctrl": "wingman-follower-ctrl", "mavlink_bridge": "wingman-mavlink"}
words = sys.argv[2].split()
pids = dict(zip(words[0::2], (int(w) for w in words[1::2])))
states = {0: "STARTING", 1: "OK", 2: "DEGRADED", 3: "ERROR", 4: "STOPPING"}
seen = {}
with Udpm(sys.argv[1]) as bus:  # bounded: 600 messages or 20 s
    bus.subscribe("STATUS_.*")
    for msg in bus.messages(max_messages=600, timeout_s=20):
        s = wingman.status_t.decode(msg.data)
        if program.get(s.process) in pids and s.pid == pids[program[s.process]]:
            seen[s.process] = (msg.channel, s.pid, states.get(s.state, s.state), s.detail)
            if len(seen) == len(program):
                break
for name, (channel, pid, state, detail) in sorted(seen.items()):
    print("%s pid %d %s: %s" % (channel, pid, state, detail))
missing = sorted(set(program) - set(seen))
if missing:
    print("no heartbeat from the supervised pid of: " + ", ".join(missing))
    sys.exit(1)
PY
  then
    cat "$out/heartbeats.txt" >&2; die "heartbeats (read with the installed Python types from $pypath)"
  fi
  say "a heartbeat from each supervised pid (installed Python types, $(/usr/bin/python3 -c 'import sys; print(sys.version.split()[0])')):"
  sed 's/^/    /' "$out/heartbeats.txt"

  # 4. The flight through the supervised stack (fly.sh's simulator settings, its lockstep included).
  scenario="$src/config/scenarios/formation_2d.yaml"
  seed=$("$bin/wingman" scenario get "$scenario" seed)
  lcm-logger --lcm-url="$url" --force --quiet --channel='IMAGE_.*' --invert-channels "$out/flight.lcmlog" \
    > "$out/logger.txt" 2>&1 &
  logger_pid=$!
  t_flight=$SECONDS
  "$bin/wingman-sim" --lcm-url "$url" --log-level warn --duration "$duration" \
    --set "scenario.file=$scenario" \
    --set "sync={mode: lockstep, timeout_s: 10.0, max_speed: 5.0, wait_for: [detector, localizer, follower_ctrl], startup_timeout_s: 60.0}" \
    --set "detections={from_ground_truth: false, box: sphere, noise_px: 1.0, seed: $seed}" \
    --set render.enabled=true --set autopilot=lcm > "$out/sim.log" 2>&1 &
  sim_pid=$!
  wait "$sim_pid" || { sim_pid=""; tail -n 20 "$out/sim.log" >&2; die "wingman-sim against the supervised stack"; }
  sim_pid=""
  flight_s=$((SECONDS - t_flight))
  sleep 0.3  # the logger is outside the loop: let it take the last messages
  stop_pid "$logger_pid"; logger_pid=""
  ctl status > "$out/status_after.txt" 2>&1 || true
  for p in "${programs[@]}"; do
    now=$(ctl pid "wingman:$p")
    [ "$now" = "${pid_before[$p]}" ] || die "$p restarted during the flight (pid ${pid_before[$p]} -> $now): $(grep "$p" /var/log/supervisor/supervisord.log | tail -n 3)"
  done
  "$bin/wingman" eval "$out/flight.lcmlog" --json "$out/eval.json" --csv "$out/targets.csv" --scenario "$scenario" \
    --follower-config "$confdir/follower_ctrl.yaml" > "$out/eval.txt" 2>&1 || { cat "$out/eval.txt" >&2; die "wingman eval"; }

  # 5. The recorder's recording in the installed folder; a clean stop.
  stop_pid "$sup_pid"; sup_pid=""
  for p in "${programs[@]}"; do
    grep -q "stopped: $p (exit status 0)" /var/log/supervisor/supervisord.log ||
      die "$p: no clean stop (exit status 0) on SIGTERM to supervisord: $(grep "$p" /var/log/supervisor/supervisord.log | tail -n 2)"
  done
  recording=$(find "$recdir" -name '*.lcmlog' -size +0 | head -n 1)
  [ -n "$recording" ] || die "the supervised recorder wrote no recording in $recdir"
  echo "$recording $(stat -c %s "$recording")" > "$out/recording.txt"
  say "flight of $duration s flown in $flight_s s through the supervised stack; the recorder wrote $recording" \
      "($(stat -c %s "$recording") bytes); every program stopped with exit status 0"
  exit 0
fi

# -------------------------------------------------------------------------------------------- on the host ---
skip() { echo "$me: SKIPPED: $*"; exit 77; }
fail() { echo "$me: FAIL: $*" >&2; exit 1; }
[ "$(id -u)" = 0 ] || skip "needs root (mount and network namespaces, overlayfs)"
command -v unshare > /dev/null || skip "unshare (util-linux) is not installed"
grep -qw overlay /proc/filesystems || modprobe overlay 2>/dev/null || skip "the kernel has no overlayfs"
grep -qw overlay /proc/filesystems || skip "the kernel has no overlayfs"
if ! command -v supervisord > /dev/null || ! command -v supervisorctl > /dev/null ||
   [ ! -r /etc/supervisor/supervisord.conf ]; then
  skip "Debian's supervisor is not installed (tools/install_deps.sh installs it)"
fi
command -v lcm-logger > /dev/null || skip "lcm-logger is not installed"
[ -x /usr/bin/python3 ] || skip "Debian's python3 is not installed"
unshare --mount --net --pid --fork --kill-child --mount-proc --propagation private true 2> /dev/null ||
  skip "cannot make mount, network and pid namespaces here (unshare)"
for exe in wingman-camera-driver wingman-detector wingman-localizer wingman-follower-ctrl wingman-mavlink \
           wingman-recorder wingman wingman-sim; do
  [ -x "$build/bin/$exe" ] || fail "$build/bin/$exe is missing (build first)"
done
duration="${WINGMAN_SUPD_DURATION:-12}"
work="${3:-$(mktemp -d /tmp/wingman-installed-supd.XXXXXX)}"
mkdir -p "$work"
work=$(cd "$work" && pwd)
keep="${WINGMAN_SUPD_KEEP:-}"
[ -n "${3:-}" ] && keep=1
finish() { if [ "$keep" = 1 ]; then echo "$me: kept $work"; else rm -rf "$work"; fi; }
trap finish EXIT
# The host is not touched: these paths are as they were (present or absent) after both runs.
host_paths=(/usr/bin/wingman-detector /usr/share/wingman /usr/lib/python3/dist-packages/wingman /etc/wingman
            /etc/supervisor/conf.d/wingman.conf /opt/wingman /etc/opt/wingman /var/opt/wingman /var/log/wingman)
host_state() { local p; for p in "${host_paths[@]}"; do if [ -e "$p" ]; then echo "$p present"; else echo "$p absent"; fi; done; }
host_before=$(host_state)

SECONDS=0
for prefix in /usr /opt/wingman; do
  out="$work/run${prefix//\//_}"
  rm -rf "$out"; mkdir -p "$out"
  rc=0
  timeout --kill-after=10 240 unshare --mount --net --pid --fork --kill-child --mount-proc --propagation private -- \
    env WINGMAN_SUPD_INNER=1 "$0" "$src" "$build" "$prefix" "$out" "$duration" || rc=$?
  [ "$rc" != 77 ] || exit 77
  if [ "$rc" != 0 ]; then
    keep=1
    tail -n 30 "$out/supervisord.log" 2>/dev/null || true
    fail "--prefix $prefix (exit $rc; see $out)"
  fi
done
[ "$(host_state)" = "$host_before" ] || { keep=1; diff <(echo "$host_before") <(host_state) || true; fail "the host changed"; }

# Both prefixes, the same flight: equal figures (latency fields aside), equal targets.csv; the bounds.
# The detector's backend "auto" takes the faster of OpenCL and OpenCV's CPU path, timed at its start: under load the two
# installs can choose differently, and the two backends' boxes differ in the 4th decimal, which the closed loop carries
# on. Byte-equal flights are required when both detectors ran the same backend; otherwise both flights must keep the
# bounds and agree within stated tolerances.
a="$work/run_usr" b="$work/run_opt_wingman"
backend() { sed -n 's/.*STATUS_DETECTOR pid [0-9]* [A-Z]*: backend \([a-z-]*\).*/\1/p' "$1/heartbeats.txt" | head -n 1; }
backend_a=$(backend "$a") backend_b=$(backend "$b")
[ -n "$backend_a" ] && [ -n "$backend_b" ] || fail "no detector backend in the heartbeats ($a, $b/heartbeats.txt)"
if [ "$backend_a" = "$backend_b" ]; then
  cmp -s "$a/targets.csv" "$b/targets.csv" ||
    { keep=1; diff "$a/targets.csv" "$b/targets.csv" | head -n 10; fail "targets.csv differ (both detectors ran $backend_a)"; }
else
  echo "$me: the detectors chose different backends (/usr $backend_a, /opt/wingman $backend_b): the flights are compared" \
       "within tolerances, not byte for byte"
fi
if ! PYTHONPATH="$src/tests/support" /usr/bin/python3 - "$a/eval.json" "$b/eval.json" "$backend_a" "$backend_b" <<'PY'; then
import json, sys
from bounds import check, installed_flight_checks


def figures(node, path=""):
    """{dotted path: value} of every field but the wall-clock latencies and the detectors' backend lines (a realtime
    detector's line quotes its start-up timings)."""
    if isinstance(node, dict):
        items = node.items()
    elif isinstance(node, list):
        items = ((str(i), v) for i, v in enumerate(node))
    else:
        return {path: node}
    flat = {}
    for k, v in items:
        if "latency" not in k and k != "detector_backends":
            flat.update(figures(v, path + "." + k if path else k))
    return flat


ea, eb = (json.load(open(f)) for f in sys.argv[1:3])
same_backend = sys.argv[3] == sys.argv[4]
fa, fb = figures(ea), figures(eb)
differ = sorted(k for k in set(fa) | set(fb) if fa.get(k) != fb.get(k))
for k in differ:
    print("differs: %s: /usr %s, /opt/wingman %s" % (k, fa.get(k), fb.get(k)))
rows = [("localization RMS (m)", ("localization", "rms_m")), ("formation RMS, horizontal (m)", ("formation_horizontal", "rms_m")),
        ("target estimates", ("target_estimates",)), ("frames with the leader visible", ("frames_leader_visible",)),
        ("frames with the leader detected", ("frames_leader_detected",)), ("track ids on the leader", ("track_ids_on_leader",)),
        ("false targets", ("false_targets",)), ("latency p50 (ms, wall clock)", ("latency", "p50_ms")),
        ("latency p99 (ms, wall clock)", ("latency", "p99_ms"))]
print("installed_supervisord: the same flight under supervisord from both prefixes (%d figures compared, %d differ):"
      % (len(fa), len(differ)))
print("  %-36s %13s %14s" % ("", "--prefix /usr", "/opt/wingman"))
for name, keys in rows:
    va, vb = ea, eb
    for k in keys:
        va, vb = va[k], vb[k]
    shown = ["%.3f" % v if isinstance(v, float) else str(v) for v in (va, vb)]
    print("  %-36s %13s %14s" % (name, shown[0], shown[1]))
for name, e in (("--prefix /usr", ea), ("--prefix /opt/wingman", eb)):
    check("installed_supervisord %s" % name, installed_flight_checks(e))
if same_backend:
    sys.exit(1 if differ else 0)
# Different backends: the RMS figures within 0.05 m (localization) and 0.15 m (formation) of each other, the frame
# counts within 2 % (each backend pinned, this 12-s flight: 0.339 / 0.220 m with opencl, 0.360 / 0.293 m with cpu).
bad = []
for keys, tol in ((("localization", "rms_m"), 0.05), (("formation_horizontal", "rms_m"), 0.15)):
    va, vb = ea, eb
    for k in keys:
        va, vb = va[k], vb[k]
    if abs(va - vb) > tol:
        bad.append("%s: %.4f vs %.4f (tolerance %.2f m)" % (".".join(keys), va, vb, tol))
for key in ("target_estimates", "frames_leader_visible", "frames_leader_detected"):
    va, vb = ea[key], eb[key]
    if abs(va - vb) > 0.02 * max(va, vb):
        bad.append("%s: %d vs %d (tolerance 2 %%)" % (key, va, vb))
for b in bad:
    print("installed_supervisord: FAIL: the two backends' flights differ beyond the tolerance: " + b)
sys.exit(1 if bad else 0)
PY
  keep=1; fail "the two prefixes' flights differ (above) or are out of bounds"
fi
echo "$me: passed in $SECONDS s (host unchanged)"

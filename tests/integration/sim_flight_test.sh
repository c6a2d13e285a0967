#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# CI flight: 20 s of the 2-D formation scenario through the real processes (wingman-sim, -detector, -localizer,
# -follower-ctrl) on LCM multicast in a private network namespace, in lockstep; asserts the formation and
# localization errors stay within the bounds stated in docs/simulation.md and that the flight is flagged when its
# detections came from ground truth: the 20 s flight uses the simulator's ground-truth boxes and no images, so its
# bounds measure localization and control; `rendered` flies 2 s with rendered 1280x720 images through the detector
# process and its shipped CNN model instead; `pose_error` flies 30 s with ground-truth boxes while the follower's
# reported pose is wrong by a drifting error (tools/fly.sh --own-pose-error 0.3,0.01: 0.3 m per position axis,
# 0.01 rad per rotation, 2-s correlation), reported with its covariance, which the localizer must take into account
# (pose.use_covariance) to keep the track and the formation; `windows` flies fly_away_far (a leader flying away from
# 14 to 38 m, 13 s, rendered, the shipped CNN) with the tracker-driven windows (tools/fly.sh --windows) and checks that
# the leader is detected and tracked beyond the single pass's range; `surround` flies four cameras all around a
# leader circling at 8 m (tools/fly.sh --rig surround4: ground truth for a lap, the same lap with the cameras exposed one
# after the other, then 4 s with the CNN) and checks one track id through the hand-overs; `crossing` flies two drones
# crossing in front of the camera (config/scenarios/crossing.yaml: 25 s with ground-truth boxes, the whole 90 s with
# ground-truth boxes and four cameras all around, then 14 s with the shipped CNN, each through the first crossing at
# 10.7 s) and judges the identities inside the crossing windows;
# `motion` flies the first 6 s of config/scenarios/approach.yaml (the default quad crossing the view 43-36 m away)
# with the single pass and with the detector's motion cue (motion.enabled) and checks that the cue's track is born
# there, at least 1.3 times as far as the single pass's first (issue 31's target).
# Extra arguments go to tools/fly.sh (for runs by hand).
# Usage: sim_flight_test.sh SOURCE_DIR BIN_DIR [flight|rendered|pose_error|windows|surround|crossing|motion]
#        [fly.sh arguments...]
set -euo pipefail
src="$1"; bin="$2"; kind="${3:-flight}"
shift $(( $# < 3 ? $# : 3 ))
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
cd "$src"
fail() { echo "sim_flight_test: $1" >&2; exit 1; }
if [ "$kind" = rendered ]; then
  log=$(WINGMAN_BIN_DIR="$bin" timeout 600 tools/fly.sh --scenario formation_2d --duration 2 --render --out "$out" 2>&1) \
    || { echo "$log"; fail "the rendered flight failed"; }
  echo "$log"
  # 60 frames (t = 0 .. 1.967 s at 30 Hz): the detector handled every image and the follower every targets_t.
  "$bin/wingman" loginfo "$out/flight.lcmlog" | tee "$out/loginfo.txt"
  grep -Eq "^  detector .*handled 60, drops 0" "$out/loginfo.txt" || fail "the detector did not handle all 60 images"
  grep -Eq "^SETPOINT +setpoint_t +60 " "$out/loginfo.txt" || fail "expected 60 setpoints"
  grep -q "detections from the CNN" <<<"$log" || fail "the flight did not say its detections came from the CNN"
  grep -q '"detection_source": "cnn"' "$out/eval.json" || fail "eval.json: detection_source is not cnn"
  echo "sim_flight_test: ok"
  exit 0
fi
if [ "$kind" = windows ]; then
  log=$(WINGMAN_BIN_DIR="$bin" timeout 900 tools/fly.sh --scenario fly_away_far --windows --out "$out" "$@" 2>&1) ||
    { echo "$log"; fail "the flight failed"; }
  echo "$log"
  grep -Eq "\[sim\] info: 390 frames in .*0 lockstep timeouts" <<<"$log" ||
    fail "the simulator did not fly 390 frames in lockstep without a timeout (sync.scripted_lockstep)"
  PYENV_VERSION=system python3 - "$out/eval.json" "$out/targets.csv" <<'PY'
import csv, json, sys
r = json.load(open(sys.argv[1]))
problems = []
def check(ok, what):
    if not ok: problems.append(what)
# Bounds (docs/results.md, "Tracker-driven windows"): fly_away_far, seed 6, lockstep, the shipped CNN. Measured
# (2026-12-07, window boxes through the relation's window grid): the leader detected in 210 of 210 frames at 20-30 m
# and 58 of 59 beyond 30 m (the single pass: 44 % and 0 % on fly_away), one track id in the whole flight, targets
# within 3 m of the leader to 24.9 m (beyond, the range from 13-pixel boxes is too short: docs/results.md).
bins = {b["lo_m"]: b for b in r["detection_by_range"]}
def detected(lo):
    b = bins[lo]
    return b["detected"] / max(b["visible"], 1), b["visible"]
rate, visible = detected(20.0)
check(visible >= 150, f"{visible} frames with the leader at 20-30 m, expected >= 150")
check(rate >= 0.9, f"leader detected in {rate:.2f} of its frames at 20-30 m, expected >= 0.9")
rate30, visible30 = detected(30.0)
check(visible30 >= 40, f"{visible30} frames with the leader beyond 30 m, expected >= 40")
check(rate30 >= 0.8, f"leader detected in {rate30:.2f} of its frames beyond 30 m, expected >= 0.8")
check(r["track_ids_on_leader"] == 1, f"{r['track_ids_on_leader']} track ids on the leader, expected 1")
rows = list(csv.DictReader(open(sys.argv[2])))
ids = sorted({row["track_id"] for row in rows})
check(len(ids) == 1, f"track ids {ids} published: the leader is the only drone in view, expected one")
farthest = max((float(row["range_m"]) for row in rows if row["vehicle_id"] == "1"), default=0.0)
check(farthest >= 20.0, f"targets within 3 m of the leader only to {farthest:.1f} m, expected >= 20 m")
print("sim_flight_test: " + ("ok" if not problems else "FAILED: " + "; ".join(problems)))
print(f"sim_flight_test: measured detection at 20-30 m {rate:.3f}, beyond 30 m {rate30:.3f}, within 3 m to "
      f"{farthest:.1f} m, track ids {ids}, {r['false_targets']} targets off the leader by > 3 m")
sys.exit(1 if problems else 0)
PY
  exit
fi
if [ "$kind" = surround ]; then
  # Four cameras all around (config/rigs/surround4.yaml), a leader circling the hovering camera vehicle at 8 m: first
  # the whole lap with ground-truth boxes (fusion and tracking alone), then the first 4 s with the shipped CNN on the
  # four rendered cameras (one hand-over, from camera 0 to camera 1, at about 2.5 s).
  log=$(WINGMAN_BIN_DIR="$bin" timeout 300 tools/fly.sh --rig surround4 --scenario surround --detections truth \
    --out "$out/truth" "$@" 2>&1) || { echo "$log"; fail "the ground-truth flight failed"; }
  echo "$log"
  grep -Eq "\[sim\] info: 1080 frames in .*0 lockstep timeouts" <<<"$log" || fail "truth: not 1080 frames in lockstep"
  # The same lap with the cameras not triggered together: camera i exposes i/120 s after the frame's time.
  log=$(WINGMAN_BIN_DIR="$bin" timeout 300 tools/fly.sh --rig surround4 --scenario surround --detections truth \
    --camera-stagger 0.008333 --out "$out/staggered" "$@" 2>&1) || { echo "$log"; fail "the staggered flight failed"; }
  echo "$log"
  grep -Eq "\[sim\] info: 1080 frames in .*0 lockstep timeouts" <<<"$log" || fail "staggered: not 1080 frames in lockstep"
  log=$(WINGMAN_BIN_DIR="$bin" timeout 600 tools/fly.sh --rig surround4 --scenario surround --duration 4 \
    --out "$out/cnn" "$@" 2>&1) || { echo "$log"; fail "the CNN flight failed"; }
  echo "$log"
  grep -Eq "\[sim\] info: 120 frames in .*0 lockstep timeouts" <<<"$log" || fail "cnn: not 120 frames in lockstep"
  grep -q "image by image: 0 timeouts" <<<"$log" || fail "cnn: an image went unanswered (sync.image_by_image)"
  PYENV_VERSION=system python3 - "$out" <<'PY'
import csv, json, os, sys
problems = []
def check(ok, what):
    if not ok: problems.append(what)
def handovers(path):
    rows = [r for r in csv.DictReader(open(path)) if r["vehicle_id"] == "1"]
    last, n = {}, 0
    for r in rows:
        n += r["track_id"] in last and last[r["track_id"]] != r["camera_id"]
        last[r["track_id"]] = r["camera_id"]
    return n
# Bounds (docs/results.md, "Several cameras"). Measured 2026-12-06 (the 2-core VM): ground truth, the whole lap: 1
# track id, 0 switches, 4 hand-overs, 3-D RMS 0.053 m, 0 false targets; the CNN, 5 s: the leader detected in 149 of
# 150 frames, 1 track id, 1 hand-over (2.47 s), 3-D RMS 0.69 m (the range from the boxes), 0 false targets.
# The staggered lap (2026-12-06): 1 track id, 0 switches, 3-D RMS 0.061 m, 0 false targets, the leader boxed in 1098
# of the 1107 exposures that see it, a target published after every camera's exposure (4281: 1070-1071 at each of
# the four exposure times of a frame; hand-overs 52, as near a boundary the last detection alternates by exposure).
for name, rms_max, min_handovers, min_rate in (("truth", 0.15, 4, 0.99), ("staggered", 0.15, 4, 0.97),
                                               ("cnn", 1.2, 1, 0.9)):
    d = os.path.join(sys.argv[1], name)
    r = json.load(open(os.path.join(d, "eval.json")))
    rate = r["frames_leader_detected"] / max(r["frames_leader_visible"], 1)
    h = handovers(os.path.join(d, "targets.csv"))
    check(rate >= min_rate, f"{name}: leader detected in {rate:.3f} of its frames, expected >= {min_rate}")
    check(r["track_ids_on_leader"] == 1, f"{name}: {r['track_ids_on_leader']} track ids on the leader, expected 1")
    check(r["leader_id_switches"] == 0, f"{name}: {r['leader_id_switches']} id switches, expected 0")
    check(h >= min_handovers, f"{name}: {h} hand-overs, expected >= {min_handovers}")
    check(r["localization"]["n"] > 0 and r["localization"]["rms_m"] <= rms_max,
          f"{name}: 3-D RMS {r['localization']['rms_m']:.3f} m (n = {r['localization']['n']}), expected <= {rms_max}")
    check(r["false_targets"] == 0, f"{name}: {r['false_targets']} false targets, expected 0")
    if name == "staggered":  # a target after each camera's exposure: the four exposure times of every frame
        phases = [0, 0, 0, 0]
        for row in csv.DictReader(open(os.path.join(d, "targets.csv"))):
            phases[round(float(row["t_s"]) * 120) % 4] += 1
        check(min(phases) >= 1000, f"staggered: targets at the four exposure times {phases}, expected >= 1000 each")
        print(f"sim_flight_test: staggered: targets at the four exposure times of a frame {phases}")
    print(f"sim_flight_test: {name}: detected {rate:.3f}, ids {r['track_ids_on_leader']}, switches "
          f"{r['leader_id_switches']}, hand-overs {h}, RMS {r['localization']['rms_m']:.3f} m, "
          f"false targets {r['false_targets']}")
print("sim_flight_test: " + ("ok" if not problems else "FAILED: " + "; ".join(problems)))
sys.exit(1 if problems else 0)
PY
  exit
fi
if [ "$kind" = crossing ]; then
  log=$(WINGMAN_BIN_DIR="$bin" timeout 300 tools/fly.sh --scenario crossing --detections truth --duration 25 \
    --out "$out/truth" "$@" 2>&1) || { echo "$log"; fail "the ground-truth flight failed"; }
  echo "$log"
  # The whole 90 s with four cameras all around (config/rigs/surround4.yaml): the other drone never leaves the view.
  log=$(WINGMAN_BIN_DIR="$bin" timeout 300 tools/fly.sh --rig surround4 --scenario crossing --detections truth \
    --out "$out/truth4" "$@" 2>&1) || { echo "$log"; fail "the four-camera ground-truth flight failed"; }
  echo "$log"
  grep -Eq "\[sim\] info: 2700 frames in .*0 lockstep timeouts" <<<"$log" || fail "truth4: not 2700 frames in lockstep"
  log=$(WINGMAN_BIN_DIR="$bin" timeout 600 tools/fly.sh --scenario crossing --duration 14 --out "$out/cnn" "$@" 2>&1) ||
    { echo "$log"; fail "the CNN flight failed"; }
  echo "$log"
  grep -Eq "\[sim\] info: 420 frames in .*0 lockstep timeouts" <<<"$log" || fail "cnn: not 420 frames in lockstep"
  PYTHONPATH="$bin/../python:$src/python" PYENV_VERSION=system python3 - "$out" <<'PY'
import csv, json, os, sys
from wingman_lcm.log import read_log
import wingman
problems = []
def check(ok, what):
    if not ok: problems.append(what)
# Bounds (docs/results.md, "Two drones crossing"). Measured 2026-12-07 (the 2-core VM), the first crossing at 10.7 s:
# ground truth, 25 s (vehicle 2 also leaves the view for 4.7 s and is re-acquired): each drone 1 track id, 0 switches,
# 3-D RMS 0.104 m, 0 false targets; ground truth with four cameras, the whole 90 s (four crossings): each drone 1 track
# id, 0 switches, 3-D RMS 0.123 m, 0 false targets; the CNN, 14 s: each drone 1 track id, 0 switches, 3-D RMS 0.878 m,
# 73 false targets (2 ids: range settling and the crossing), the follower on one track throughout.
for name, rms_max, false_max in (("truth", 0.2, 0), ("truth4", 0.2, 0), ("cnn", 1.3, 150)):
    d = os.path.join(sys.argv[1], name)
    r = json.load(open(os.path.join(d, "eval.json")))
    for v in ("1", "2"):
        ids = r["ids_by_vehicle"].get(v, {"track_ids": 0, "id_switches": 0})
        check(ids["track_ids"] == 1, f"{name}: vehicle {v}: {ids['track_ids']} track ids, expected 1")
        check(ids["id_switches"] == 0, f"{name}: vehicle {v}: {ids['id_switches']} id switches, expected 0")
    drones_of = {}
    for row in csv.DictReader(open(os.path.join(d, "targets.csv"))):
        if row["vehicle_id"] != "-1":
            drones_of.setdefault(row["track_id"], set()).add(row["vehicle_id"])
    both = sorted(t for t, v in drones_of.items() if len(v) > 1)
    check(not both, f"{name}: track ids {both} matched to both drones")
    loc = r["localization"]
    check(loc["n"] > 0 and loc["rms_m"] <= rms_max, f"{name}: 3-D RMS {loc['rms_m']:.3f} m (n = {loc['n']}), expected <= {rms_max}")
    check(r["false_targets"] <= false_max, f"{name}: {r['false_targets']} false targets, expected <= {false_max}")
    followed = [wingman.setpoint_t.decode(e.data).target_track_id
                for e in read_log(os.path.join(d, "flight.lcmlog")) if e.channel == "SETPOINT"]
    chosen = sorted({t for t in followed if t > 0})
    check(len(chosen) == 1, f"{name}: the follower followed track ids {chosen}, expected one")
    print(f"sim_flight_test: {name}: ids by vehicle {r['ids_by_vehicle']}, RMS {loc['rms_m']:.3f} m, "
          f"false targets {r['false_targets']}, followed {chosen}")
print("sim_flight_test: " + ("ok" if not problems else "FAILED: " + "; ".join(problems)))
sys.exit(1 if problems else 0)
PY
  exit
fi
if [ "$kind" = motion ]; then
  for flight in single motion; do
    sets=()
    if [ "$flight" = motion ]; then sets=(--detector-set motion.enabled=true); fi
    log=$(WINGMAN_BIN_DIR="$bin" timeout 600 tools/fly.sh --scenario approach --duration 6 "${sets[@]}" \
      --out "$out/$flight" "$@" 2>&1) || { echo "$log"; fail "the $flight flight failed"; }
    echo "$log"
    grep -Eq "\[sim\] info: 180 frames in .*0 lockstep timeouts" <<<"$log" || fail "$flight: not 180 frames in lockstep"
    # Scored again matching within 15 m: the only drone in view, and a far track's range is 20-27 % short
    # (docs/results.md, "The motion cue"), so its targets are more than 3 m off.
    "$bin/wingman" eval "$out/$flight/flight.lcmlog" --match-radius 15 --csv "$out/$flight/targets_r15.csv" \
      > "$out/$flight/eval_r15.txt" || { cat "$out/$flight/eval_r15.txt"; fail "$flight: wingman eval failed"; }
  done
  PYENV_VERSION=system python3 - "$out" <<'PY'
import csv, os, sys
problems = []
def check(ok, what):
    if not ok: problems.append(what)
def first_target(name):  # (time s, true range m) of the first published target within 15 m of the leader, or None
    for row in csv.DictReader(open(os.path.join(sys.argv[1], name, "targets_r15.csv"))):
        if row["vehicle_id"] == "1":
            return float(row["t_s"]), float(row["range_m"])
    return None
# Bounds (docs/results.md, "The motion cue"). Measured 2026-12-07 (the 2-core VM), the first 6 s of approach: the
# single pass no target on the leader (its first comes at 21.2 s, 20.4 m, in the whole flight); the motion cue its
# first at 2.7 s, 40.7 m.
single, motion = first_target("single"), first_target("motion")
check(motion is not None, "motion: no target on the leader in 6 s")
if motion is not None:
    check(motion[1] >= 30.0, f"motion: the leader's first target at {motion[1]:.1f} m, expected >= 30 m")
    if single is not None:
        check(motion[1] >= 1.3 * single[1],
              f"motion: first target at {motion[1]:.1f} m, single pass at {single[1]:.1f} m: expected >= 1.3 times")
print(f"sim_flight_test: the leader's first target (time s, true range m): single pass {single}, motion cue {motion}")
print("sim_flight_test: " + ("ok" if not problems else "FAILED: " + "; ".join(problems)))
sys.exit(1 if problems else 0)
PY
  exit
fi
if [ "$kind" = pose_error ]; then
  log=$(WINGMAN_BIN_DIR="$bin" timeout 600 tools/fly.sh --scenario formation_2d --duration 30 --detections truth \
    --own-pose-error 0.3,0.01 --out "$out" "$@" 2>&1) || { echo "$log"; fail "the flight failed"; }
  echo "$log"
  PYENV_VERSION=system python3 - "$out/eval.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
problems = []
def check(ok, what):
    if not ok: problems.append(what)
# Bounds (docs/localization.md, "The own pose's uncertainty"): 30 s of formation_2d with the own pose wrong by
# 0.3 m / 0.01 rad (seed 1). The localization error includes the own pose's own error (0.3 m per axis, 0.52 m in 3-D)
# since the target is placed from it; the formation is flown on the same wrong pose, so much of it cancels.
check(r["truth_frames"] >= 675, f"{r['truth_frames']} ground-truth frames recorded of 900")
check(r["track_ids_on_leader"] == 1, f"{r['track_ids_on_leader']} track ids on the leader, expected 1")
check(r["false_targets"] == 0, f"{r['false_targets']} false targets")
loc, fh = r["localization"], r["formation_horizontal"]
check(loc["n"] >= 0.9 * r["truth_frames"], f"only {loc['n']} localized targets matched to truth of {r['truth_frames']}")
check(loc["rms_m"] <= 0.75, f"localization RMS {loc['rms_m']:.3f} m > 0.75 m")
check(fh["rms_m"] <= 0.5, f"formation horizontal RMS {fh['rms_m']:.3f} m > 0.5 m")
print("sim_flight_test: " + ("ok" if not problems else "FAILED: " + "; ".join(problems)))
print(f"sim_flight_test: measured localization RMS {loc['rms_m']:.3f} m (n {loc['n']}), formation horizontal RMS "
      f"{fh['rms_m']:.3f} m, {r['track_ids_on_leader']} id(s), {r['false_targets']} false targets")
sys.exit(1 if problems else 0)
PY
  exit
fi
log=$(WINGMAN_BIN_DIR="$bin" timeout 600 tools/fly.sh --scenario formation_2d --duration 20 --detections truth --out "$out" "$@" 2>&1) || { echo "$log"; fail "the flight failed"; }
echo "$log"
[ -s "$out/eval.json" ] || fail "no eval.json"
[ -s "$out/report.html" ] || fail "no report.html"
grep -q '<svg id="topdown"' "$out/report.html" || fail "the report has no top-down plot"
PYENV_VERSION=system python3 - "$out/eval.json" "$bin" <<'PY'
import json, os, sys
r = json.load(open(sys.argv[1]))
problems = []
def check(ok, what):
    if not ok: problems.append(what)
# Bounds (docs/simulation.md): 20 s of formation_2d, lockstep, 0.1 s command delay, 1 px edge noise.
# The simulator's own count says the flight was 20 s (checked below); the log may lack a lost tail (seen once: the
# logger recorded 17.3 s of 20 on a loaded machine), so the recorded span only has to cover most of it.
check(r["duration_s"] >= 15.0, f"the log spans {r['duration_s']} s of the 20 s flight")
# lcm-logger may lose some messages when the machine is saturated (seen before tools/fly.sh paced the simulator at
# 5x real time: 512 and 383 of 600 under parallel load; since, 600 of 600 in 10 runs beside six busy loops); the
# error bounds hold on what was recorded, and the count must stay well above half.
check(r["truth_frames"] >= 450, f"{r['truth_frames']} ground-truth frames recorded of 600")
if r["truth_frames"] < 600: print(f"sim_flight_test: note: the logger recorded {r['truth_frames']} of 600 ground-truth frames")
check(r["track_ids_on_leader"] == 1, f"{r['track_ids_on_leader']} track ids on the leader, expected 1")
check(r["false_targets"] == 0, f"{r['false_targets']} false targets")
loc, fh, fv = r["localization"], r["formation_horizontal"], r["formation_vertical"]
check(loc["n"] >= 0.8 * r["truth_frames"], f"only {loc['n']} localized targets matched to truth")
check(loc["rms_m"] <= 0.2, f"localization RMS {loc['rms_m']:.3f} m > 0.2 m")
check(fh["n"] >= 0.6 * r["truth_frames"], f"only {fh['n']} formation samples")
check(fh["rms_m"] <= 0.3, f"formation horizontal RMS {fh['rms_m']:.3f} m > 0.3 m")
check(fh["max_m"] <= 0.75, f"formation horizontal max {fh['max_m']:.3f} m > 0.75 m")
check(fv["max_m"] <= 0.1, f"formation vertical max {fv['max_m']:.3f} m > 0.1 m")
check(r["detection_source"] == "ground_truth", f"detection_source {r['detection_source']}, expected ground_truth")
print("sim_flight_test: " + ("ok" if not problems else "FAILED: " + "; ".join(problems)))
sys.exit(1 if problems else 0)
PY
grep -q "SIMULATOR'S GROUND TRUTH" <<<"$log" || fail "the flight did not say its detections came from ground truth"
grep -Eq "\[sim\] info: 600 frames in .*0 lockstep timeouts; setpoints 600 on time" <<<"$log" ||
  fail "the simulator did not fly 600 frames with every setpoint on time"

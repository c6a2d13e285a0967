#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# tools/experiment_summary.py on real `wingman eval` output: a synthetic flight log (wingman-write-report-flight,
# fixed seed) is evaluated, and every experiment's summary is made from it; the tables must carry the eval's numbers
# beside the thesis's figures.
# Usage: experiment_summary_test.sh SOURCE_DIR WINGMAN WRITE_REPORT_FLIGHT
set -euo pipefail
src="$1" wingman="$2" write_flight="$3"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "experiment_summary_test: FAIL: $*" >&2; exit 1; }
export PYENV_VERSION=system WINGMAN_BIN_DIR=$(dirname "$wingman")
summary="$src/tools/experiment_summary.py"

mkdir -p "$work/run"
"$write_flight" "$work/run/flight.lcmlog"
"$wingman" eval "$work/run/flight.lcmlog" --json "$work/run/eval.json" --csv "$work/run/targets.csv" --quiet > /dev/null
run="$work/run/eval.json"
val() { python3 -c "import json,sys; r=json.load(open('$1')); print(eval(sys.argv[1]))" "$2"; }

for kind in static_sweep calibration distance follow_1d formation_2d max_range; do mkdir -p "$work/$kind"; done
python3 "$summary" static_sweep "$work/static_sweep" "$run" "$run" "$run" > /dev/null
python3 "$summary" calibration "$work/calibration" 0.25 "$run" > /dev/null
python3 "$summary" distance "$work/distance" "$run" "$run" "$run" "$run" > /dev/null
python3 "$summary" follow_1d "$work/follow_1d" "$run" > /dev/null
python3 "$summary" formation_2d "$work/formation_2d" "$run" "$run" "$run" > /dev/null
python3 "$summary" max_range "$work/max_range" "$run" > /dev/null

# Formation: the average of three identical runs is the run's RMS; the thesis's column is there.
rms=$(val "$run" "r['localization']['rms_m']")
avg=$(val "$work/formation_2d/results.json" "r['average_rms_m']")
python3 -c "import sys; sys.exit(0 if abs($rms - $avg) < 1e-9 and $rms > 0 else 1)" || fail "average $avg != run $rms"
grep -q "^| average | 2.86 | $(printf '%.3f' "$rms") |" "$work/formation_2d/results.md" || fail "formation table: $(cat "$work/formation_2d/results.md")"
# Static sweep: the single-pass mean box-width error of the eval, as a fraction of the width.
single=$(val "$run" "'%.4f' % r['box_width_single']['mean']")
grep -q "^| single detection | 0.026 | $single (n = " "$work/static_sweep/results.md" || fail "sweep table: $(cat "$work/static_sweep/results.md")"
# The zoom-in flight over every box: its re-detected and its single-pass boxes together (the same run given as both
# flights: the eval's zoom and single counts added, the mean weighted by them).
all=$(val "$run" "'%.4f (n = %d)' % ((r['box_width_single']['n'] * r['box_width_single']['mean'] + r['box_width_zoom']['n'] * r['box_width_zoom']['mean']) / (r['box_width_single']['n'] + r['box_width_zoom']['n']), r['box_width_single']['n'] + r['box_width_zoom']['n'])")
grep -q "^| zoom-in flight, every box (re-detected or kept from the single pass) | — | $all |" "$work/static_sweep/results.md" || fail "sweep every-box row, want $all: $(cat "$work/static_sweep/results.md")"
# The range scale side-on and, from the optional third flight, from behind (here the same flight: the same scale).
k=$(val "$work/static_sweep/results.json" "'%.3f' % r['range_scale']['single']")
kb=$(val "$work/static_sweep/results.json" "'%.3f' % r['range_scale']['behind']")
[ "$k" = "$kb" ] || fail "range scale side-on $k, from behind $kb: the same flight"
grep -q "^Seen from behind .*range scale $kb (n = " "$work/static_sweep/results.md" || fail "no from-behind line: $(cat "$work/static_sweep/results.md")"
# Without the third flight the summary still works and says nothing about the view from behind.
mkdir -p "$work/static_sweep2"
python3 "$summary" static_sweep "$work/static_sweep2" "$run" "$run" > /dev/null
! grep -q "Seen from behind" "$work/static_sweep2/results.md" || fail "a from-behind line without that flight"
# Calibration: the radius flown times the median true / estimated range of the leader's targets, computed here from
# the eval's own targets.csv.
want=$(python3 - "$work/run/targets.csv" <<'PY'
import csv, sys
r = sorted(float(x["range_m"]) / float(x["range_est_m"]) for x in csv.DictReader(open(sys.argv[1]))
           if x["vehicle_id"] == "1" and float(x["range_est_m"] or 0) > 0)
print("%.6f %d" % (0.25 * r[len(r) // 2], len(r)))
PY
)
got=$(val "$work/calibration/results.json" "'%.6f %d' % (r['radius_m'], r['n'])")
[ "$got" = "$want" ] || fail "calibrated radius and count $got, want $want"
grep -q "^| radius that would make it 1 (m) | $(printf "%.3f" "${want% *}") |" "$work/calibration/results.md" || fail "calibration table: $(cat "$work/calibration/results.md")"
if python3 "$summary" calibration "$work/calibration" abc "$run" 2> "$work/err"; then fail "radius 'abc' accepted"; fi
grep -q "radius 'abc': expected metres" "$work/err" || fail "bad radius not named: $(cat "$work/err")"
# Distance: the along-the-line-of-sight mean and max.
along=$(val "$run" "'%.2f / %.2f' % (r['along_line_of_sight']['mean_m'], r['along_line_of_sight']['max_m'])")
grep -q "^| single detection, unfiltered | 1.59 / 19.77 | $along |" "$work/distance/results.md" || fail "distance table: $(cat "$work/distance/results.md")"
# 1-D follow and max range: the tables exist with the thesis's figures.
grep -q "^| mean absolute X error | 1.12 m |" "$work/follow_1d/results.md" || fail "follow table"
grep -q "≈ 13.75 m" "$work/max_range/results.md" || fail "range table"
python3 -c "import json; r=json.load(open('$work/max_range/results.json')); assert r['bins'] and sum(b['visible'] for b in r['bins']) > 0" || fail "max_range has no bins"
# Suite (issue 29): one row per flight from its eval.json, targets.csv and the scenario's drawing; the RMS is the eval's,
# the bins are the leader's targets by true range, and the bounds fail the summary (exit 1) naming the flight.
mkdir -p "$work/suite/scenarios" "$work/suite/s1001"
cp "$work/run/eval.json" "$work/run/targets.csv" "$work/suite/s1001/"
echo '{"seed": 1001, "airframe": "procedural quad", "view": "side", "lighting": "A", "duration_s": 30.0, "legs": 4,
 "offset_m": [0, -6, 0], "offset_distance_m": 6.0, "bounding_radius_m": 0.348}' > "$work/suite/scenarios/s1001.json"
python3 "$summary" suite "$work/suite" --max-rms 1000 --max-false 1000000 "$work/suite/s1001/eval.json" > /dev/null \
  || fail "suite within loose bounds failed"
want_near=$(python3 - "$work/run/targets.csv" <<'PY'
import csv, sys
e = [float(x["error_m"]) for x in csv.DictReader(open(sys.argv[1])) if x["vehicle_id"] == "1" and float(x["range_m"]) < 10]
print("%.2f (n = %d)" % ((sum(v * v for v in e) / len(e)) ** 0.5, len(e)) if e else "— (n = 0)")
PY
)
grep -q "^| s1001 | procedural quad | side | A | 6.0 | [0-9]* | $(printf '%.3f' "$rms") | $want_near |" "$work/suite/results.md" \
  || fail "suite row, want RMS $rms and below 10 m $want_near: $(cat "$work/suite/results.md")"
if python3 "$summary" suite "$work/suite" --max-rms 0.0001 "$work/suite/s1001/eval.json" > "$work/out" 2>&1; then
  fail "suite bound 0.0001 m passed"
fi
grep -q "BROKEN: s1001: 3-D RMS" "$work/out" || fail "broken bound not named: $(cat "$work/out")"

# Approach (issue 31's motion cue): per flight folder, the leader's first target (targets_r15.csv's first row on
# vehicle 1: time and true range) and the eval's false targets.
for f in single motion; do
  mkdir -p "$work/approach/$f"
  cp "$work/run/eval.json" "$work/approach/$f/eval.json"
  cp "$work/run/eval.json" "$work/approach/$f/eval_r15.json"
  cp "$work/run/targets.csv" "$work/approach/$f/targets_r15.csv"
done
python3 "$summary" approach "$work/approach" "$work/approach/single" "$work/approach/motion" > /dev/null
first=$(python3 - "$work/run/targets.csv" <<'PY'
import csv, sys
r = [x for x in csv.DictReader(open(sys.argv[1])) if x["vehicle_id"] == "1"][0]
print("%.1f s, %.1f m" % (float(r["t_s"]), float(r["range_m"])))
PY
)
false_targets=$(val "$run" "r['false_targets']")
grep -q "^| motion | $first | .* | $false_targets / $false_targets |" "$work/approach/results.md" \
  || fail "approach row, want first target $first and $false_targets false: $(cat "$work/approach/results.md")"

# Surround (issue 31's several cameras): the leader's hand-overs are its track's camera changing between targets
# (targets.csv's camera_id); the ids and RMS are the eval's.
mkdir -p "$work/surround/rig"
cp "$work/run/eval.json" "$work/surround/rig/eval.json"
python3 - "$work/run/targets.csv" "$work/surround/rig/targets.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
leader = [r for r in rows if r["vehicle_id"] == "1"]
for i, r in enumerate(leader):  # the leader's targets by camera 0, 1, 1, 2, 2, ...: one hand-over at each change
    r["camera_id"] = str((i + 1) // 2 % 4)
w = csv.DictWriter(open(sys.argv[2], "w", newline=""), fieldnames=list(rows[0].keys()))
w.writeheader()
w.writerows(rows)
PY
python3 "$summary" surround "$work/surround" "$work/surround/rig" > /dev/null
want=$(python3 - "$work/run/targets.csv" <<'PY'
import csv, sys
leader = [r for r in csv.DictReader(open(sys.argv[1])) if r["vehicle_id"] == "1"]
by_track = {}
for i, r in enumerate(leader):
    by_track.setdefault(r["track_id"], []).append((i + 1) // 2 % 4)
print(sum(sum(1 for a, b in zip(c, c[1:]) if a != b) for c in by_track.values()))
PY
)
[ "$want" -gt 0 ] || fail "the test flight has no leader targets to hand over"
got=$(val "$work/surround/results.json" "r['rig']['handovers']")
[ "$got" = "$want" ] || fail "surround hand-overs: $got, want $want"
ids=$(val "$run" "r['track_ids_on_leader']")
grep -q "^| rig | .* | $ids | " "$work/surround/results.md" || fail "surround row: $(cat "$work/surround/results.md")"

# Wrong arguments: the usage, not a traceback.
if python3 "$summary" formation_2d "$work" "$run" 2> "$work/err"; then fail "two runs accepted"; fi
grep -q "Usage" "$work/err" || fail "no usage on bad arguments: $(cat "$work/err")"
if python3 "$summary" follow_1d "$work" "$work/missing.json" 2> "$work/err"; then fail "missing file accepted"; fi
grep -q "missing.json" "$work/err" || fail "missing file not named: $(cat "$work/err")"
echo "experiment_summary_test: ok"

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Flies a simulated scenario through the real pipeline: wingman-sim (camera + autopilot stand-in), wingman-detector,
# wingman-localizer and wingman-follower-ctrl as separate processes on LCM multicast inside a private network
# namespace, in lockstep (deterministic). Records the bus, prints the localization and formation errors and writes an
# HTML report. Needs a build (tools/build.sh); the README's main command (tools/demo.sh) builds first.
#
# Usage: tools/fly.sh [--scenario NAME|FILE] [--out DIR] [--duration S] [--detections cnn|truth]
#                     [--render|--no-render] [--record-images] [--truth-box sphere|silhouette] [--zoom-in]
#                     [--flip-fusion] [--coarse-pass] [--windows] [--localizer-config FILE] [--follower-config FILE]
#                     [--render-config FILE] [--autopilot lcm|mavlink] [--firmware px4|ardupilot]
#                     [--own-pose-error M,RAD[,TAU]]
#   --scenario       config/scenarios/NAME.yaml or a file (default formation_2d)
#   --out            output folder (default build/flights/NAME)
#   --duration       stop after S simulated seconds (default: the scenario's own length)
#   --detections     cnn: the detector process finds the leader in the rendered images with the shipped model
#                    (default; WINGMAN_MODEL_CFG / WINGMAN_MODEL_WEIGHTS choose another); truth: the simulator
#                    publishes boxes projected from ground truth (flagged as such in every message down to the
#                    setpoints) and the detector runs without a model: measures localization and control alone
#   --render         render the camera images (1280x720, 0.1-0.5 s a frame on llvmpipe here); always with cnn
#   --no-render      no images (ground-truth detections need none); the default with truth
#   --record-images  also record the camera images in the log (2.7 MB per 1280x720 frame)
#   --truth-box      ground-truth detections: the bounding sphere's exact box, the localizer's model (default), or
#                    the drone's silhouette box (what a perfect detector draws; see docs/simulation.md for the bias)
#   --zoom-in        the detector re-detects each box in a full-resolution crop (Algorithm 2's zoom-in)
#   --flip-fusion    the detector also detects in the mirrored frame and fuses both passes' boxes (docs/detector.md)
#   --coarse-pass    the detector also detects at half the network input and fuses its large boxes (close drones)
#   --windows        tracker-driven windows: the localizer publishes where its tracks will be in the next frame and
#                    the detector searches there at full resolution when the single pass would see them too small
#                    (windows.* of both; docs/detector.md); the simulator keeps lockstep with a scripted camera too
#   --localizer-config  the localizer's config (default: config/flights/NAME.localizer.yaml if any, else the
#                    defaults: the leader's bounding radius, and the shipped model's box relation for cnn boxes)
#   --follower-config   the follower's config (default: config/flights/NAME.follower_ctrl.yaml if any, else the
#                    defaults); its formation.offset_m is also the offset the formation error is measured against
#   --render-config  the simulator's render.* keys (lighting, scene) from this file (wingman-sim --render-config),
#                    e.g. FILE.render.yaml written by `wingman scenario random` beside its scenario
#   --autopilot      lcm: the simulator takes SETPOINT and publishes OWN_POSE itself (default); mavlink: the
#                    simulator is a MAVLink vehicle on UDP loopback (inside the namespace) and wingman-mavlink bridges
#                    it (config/mavlink_bridge.sim.yaml): OWN_POSE from its telemetry, setpoints through OFFBOARD/GUIDED
#   --firmware       with --autopilot mavlink: the simulated autopilot's rules, px4 (OFFBOARD, default) or ardupilot
#   --own-pose-error the follower's reported pose is wrong by a drifting error (Gauss-Markov, correlation time TAU
#                    seconds, default 2) of M metres per position axis and RAD radians per rotation (standard
#                    deviations; wingman-sim's own_pose.* keys), reported with its covariance as an autopilot's
#                    ODOMETRY would be; the camera sees from the truth
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
bin="${WINGMAN_BIN_DIR:-$src/build/bin}"

scenario=formation_2d out="" duration="" render=auto record_images=false truth_box=sphere detections=cnn
zoom_in=false flip_fusion=false coarse_pass=false windows=false localizer_config="" follower_config="" render_config=""
autopilot=lcm firmware=px4 own_pose_error=""
while [ $# -gt 0 ]; do
  case "$1" in
    --scenario) scenario="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --duration) duration="$2"; shift 2 ;;
    --detections) detections="$2"; shift 2 ;;
    --zoom-in) zoom_in=true; shift ;;
    --flip-fusion) flip_fusion=true; shift ;;
    --coarse-pass) coarse_pass=true; shift ;;
    --windows) windows=true; shift ;;
    --localizer-config) localizer_config=$(realpath "$2"); shift 2 ;;
    --follower-config) follower_config=$(realpath "$2"); shift 2 ;;
    --render-config) render_config=$(realpath "$2"); shift 2 ;;
    --autopilot) autopilot="$2"; shift 2 ;;
    --firmware) firmware="$2"; shift 2 ;;
    --own-pose-error) own_pose_error="$2"; shift 2 ;;
    --no-render) render=false; shift ;;
    --render) render=true; shift ;;
    --record-images) record_images=true; shift ;;
    --truth-box) truth_box="$2"; shift 2 ;;
    -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "fly: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
if [ -f "$scenario" ]; then scenario_file=$(realpath "$scenario"); name=$(basename "$scenario" .yaml)
else scenario_file="$src/config/scenarios/$scenario.yaml"; name="$scenario"; fi
case "$truth_box" in sphere|silhouette) ;; *) echo "fly: --truth-box '$truth_box': expected sphere or silhouette" >&2; exit 2 ;; esac
case "$detections" in cnn|truth) ;; *) echo "fly: --detections '$detections': expected cnn or truth" >&2; exit 2 ;; esac
case "$autopilot" in lcm|mavlink) ;; *) echo "fly: --autopilot '$autopilot': expected lcm or mavlink" >&2; exit 2 ;; esac
case "$firmware" in px4|ardupilot) ;; *) echo "fly: --firmware '$firmware': expected px4 or ardupilot" >&2; exit 2 ;; esac
own_pose_sets=()
if [ -n "$own_pose_error" ]; then  # the values are checked by wingman-sim's config loader (own_pose.*)
  IFS=, read -r pose_m pose_rad pose_tau pose_extra <<< "$own_pose_error"
  [ -n "$pose_m" ] && [ -n "$pose_rad" ] && [ -z "$pose_extra" ] ||
    { echo "fly: --own-pose-error '$own_pose_error': expected M,RAD or M,RAD,TAU (e.g. 0.3,0.01)" >&2; exit 2; }
  own_pose_sets=(--set "own_pose.position_std_m=$pose_m" --set "own_pose.attitude_std_rad=$pose_rad"
                 --set "own_pose.correlation_time_s=${pose_tau:-2.0}")
fi
[ -r "$scenario_file" ] || { echo "fly: no scenario '$scenario' (looked for $scenario_file)" >&2; exit 2; }
out="${out:-$src/build/flights/$name}"
exes=(wingman-sim wingman-detector wingman-localizer wingman-follower-ctrl wingman)
[ "$autopilot" = lcm ] || exes+=(wingman-mavlink)
for exe in "${exes[@]}"; do
  [ -x "$bin/$exe" ] || { echo "fly: $bin/$exe is missing: build first (tools/build.sh)" >&2; exit 2; }
done

if [ "${WINGMAN_IN_NETNS:-}" != "1" ]; then
  again=(--scenario "$scenario_file" --out "$out" --detections "$detections" --truth-box "$truth_box"
         --autopilot "$autopilot" --firmware "$firmware")
  [ -z "$duration" ] || again+=(--duration "$duration")
  [ "$render" != true ] || again+=(--render)
  [ "$render" != false ] || again+=(--no-render)
  [ "$record_images" != true ] || again+=(--record-images)
  [ "$zoom_in" != true ] || again+=(--zoom-in)
  [ "$flip_fusion" != true ] || again+=(--flip-fusion)
  [ "$coarse_pass" != true ] || again+=(--coarse-pass)
  [ "$windows" != true ] || again+=(--windows)
  [ -z "$localizer_config" ] || again+=(--localizer-config "$localizer_config")
  [ -z "$follower_config" ] || again+=(--follower-config "$follower_config")
  [ -z "$render_config" ] || again+=(--render-config "$render_config")
  [ -z "$own_pose_error" ] || again+=(--own-pose-error "$own_pose_error")
  exec tools/netns_run.sh "$0" "${again[@]}"
fi
for f in "$localizer_config" "$follower_config" "$render_config"; do
  [ -z "$f" ] || [ -r "$f" ] || { echo "fly: $f: cannot read it (--localizer-config, --follower-config or --render-config)" >&2; exit 2; }
done

mkdir -p "$out"
out=$(realpath "$out")
url="$WINGMAN_LCM_URL"
log="$out/flight.lcmlog"
rm -f "$log"

# The CNN: the detector's built-in shipped model (models/wingman-small.md) unless WINGMAN_MODEL_* name another.
model_cfg="${WINGMAN_MODEL_CFG:-builtin:wingman-small}" model_weights="${WINGMAN_MODEL_WEIGHTS:-builtin:wingman-small}"
if [ -n "${WINGMAN_MODEL_WEIGHTS:-}" ] && [ -z "${WINGMAN_MODEL_CFG:-}" ]; then
  model_cfg="${model_weights%.weights}.cfg"
  [ -r "$model_cfg" ] || { echo "fly: WINGMAN_MODEL_WEIGHTS=$model_weights has no $model_cfg beside it (set WINGMAN_MODEL_CFG)" >&2; exit 2; }
fi
if [ "$detections" = cnn ]; then
  truth_detections=false
  [ "$render" = false ] && { echo "fly: --detections cnn needs images: drop --no-render" >&2; exit 2; }
  render=true
  echo "fly: detections from the CNN ($model_cfg, $model_weights) in rendered 1280x720 images"
else
  truth_detections=true
  echo "fly: detections come from the SIMULATOR'S GROUND TRUTH ($truth_box boxes, 1 px edge noise; flagged" \
       "source=SOURCE_GROUND_TRUTH in detections, targets and setpoints); the detector process runs without a model"
  [ "$render" = auto ] && render=false
  [ "$render" = false ] && echo "fly: images are not rendered (ground-truth detections need none; --render renders them)"
fi

# The box noise follows the scenario's seed (as the rendered noise does), so runs of different seeds differ.
scenario_seed=$("$bin/wingman" scenario get "$scenario_file" seed)  # read and checked by the simulator's loader

# Per-flight configs: the process defaults, plus config/flights/<scenario>.<process>.yaml where one exists.
# flight_cfg PROCESS: sets cfg_args to (--config FILE) where that file exists, else to nothing.
flight_cfg() { local f="$src/config/flights/$name.$1.yaml"; cfg_args=(); if [ -r "$f" ]; then cfg_args=(--config "$f"); fi; }
if [ -n "$localizer_config" ]; then localizer_args=(--config "$localizer_config"); else flight_cfg localizer; localizer_args=("${cfg_args[@]}"); fi
[ "$windows" != true ] || localizer_args+=(--set windows.publish=true)
if [ -n "$follower_config" ]; then follower_args=(--config "$follower_config"); else flight_cfg follower_ctrl; follower_args=("${cfg_args[@]}"); fi
# wingman eval reads the same follower configuration (its --follower-config) and the scenario for its target.
follower_eval_args=(); [ ${#follower_args[@]} -eq 0 ] || follower_eval_args=(--follower-config "${follower_args[1]}")
# Lockstep, paced at most 5x real time: the logger is outside the loop. Unpaced, a truth-mode flight ran ~2600
# frames/s and a loaded machine's logger recorded 383 of 600 ground-truth frames; at 10x, 505-600 of 600 with six
# busy loops beside it; at 5x, 600 of 600 in each of 10 such runs. Slower flights (rendering, the CNN) are not affected.
wait_for="[detector, localizer, follower_ctrl]"
[ "$autopilot" = lcm ] || wait_for="[detector, localizer, follower_ctrl, mavlink_bridge]"
# The simulator: its defaults with these keys over them (--set, read by its config loader, as for every process).
sim_sets=(--set "scenario.file=$scenario_file"
  --set "sync={mode: lockstep, timeout_s: 10.0, max_speed: 5.0, wait_for: $wait_for, startup_timeout_s: 60.0, scripted_lockstep: $windows}"
  --set "detections={from_ground_truth: $truth_detections, box: $truth_box, noise_px: 1.0, seed: $scenario_seed}"
  --set "render.enabled=$render" --set "autopilot=$autopilot"
  --set "mavlink={firmware: $firmware, streams: [odometry, attitude_quaternion, local_position_ned]}"
  "${own_pose_sets[@]}")
# The flight's effective simulator configuration, as the loader merged it (a record; the process reads the --set).
"$bin/wingman-sim" "${sim_sets[@]}" --print-config > "$out/sim.yaml"
# The detector: its defaults with these keys over them (--set, read by its config loader).
detector_args=(--set input.mode=replay)
if [ "$detections" = cnn ]; then
  detector_args+=(--set "model.cfg=\"$model_cfg\"" --set "model.weights=\"$model_weights\"" --set "detection.zoom_in=$zoom_in"
                  --set "detection.flip_fusion=$flip_fusion" --set "detection.coarse_pass=$coarse_pass"
                  --set "windows.enabled=$windows")
else
  detector_args+=(--set 'model.weights=""')
fi

pids=() logger_pid=""
# Stop the pipeline first (each process publishes a last STOPPING status), then the logger.
cleanup() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  if [ -n "$logger_pid" ]; then sleep 0.3; kill -TERM "$logger_pid" 2>/dev/null || true; wait "$logger_pid" || true; fi
}
trap cleanup EXIT

echo "fly: scenario $name, LCM bus $url (private network namespace), output in $out"
logger_args=(--lcm-url="$url" --force --quiet)
[ "$record_images" = true ] || logger_args+=(--channel='IMAGE_.*' --invert-channels)
lcm-logger "${logger_args[@]}" "$log" & logger_pid=$!
"$bin/wingman-detector" --lcm-url "$url" "${detector_args[@]}" --log-level warn & pids+=($!)
"$bin/wingman-localizer" --lcm-url "$url" "${localizer_args[@]}" --log-level warn & pids+=($!)
"$bin/wingman-follower-ctrl" --lcm-url "$url" "${follower_args[@]}" --log-level warn & pids+=($!)
if [ "$autopilot" = mavlink ]; then
  echo "fly: the autopilot is the simulator as a MAVLink vehicle ($firmware rules) through wingman-mavlink over UDP on loopback"
  "$bin/wingman-mavlink" --lcm-url "$url" --config "$src/config/mavlink_bridge.sim.yaml" --log-level info & pids+=($!)
fi

sim_args=(--lcm-url "$url" "${sim_sets[@]}")
[ -n "$duration" ] && sim_args+=(--duration "$duration")
[ -n "$render_config" ] && sim_args+=(--render-config "$render_config")
SECONDS=0
"$bin/wingman-sim" "${sim_args[@]}"
wall=$SECONDS
cleanup
pids=() logger_pid=""
trap - EXIT

# The formation error is measured against the follower's own target: wingman eval reads the follower's configuration
# (formation.offset_m) and, for the 1-D follow, the scenario's start (the leader moved back to the follower's line).
eval_args=("$log" --report "$out/report.html" --json "$out/eval.json" --csv "$out/targets.csv" --title "Wingman flight: $name"
           --scenario "$scenario_file" "${follower_eval_args[@]}")
echo
echo "fly: $name flown in $wall s of wall-clock time; errors against ground truth:"
"$bin/wingman" eval "${eval_args[@]}"
echo "fly: log $log, report $out/report.html"

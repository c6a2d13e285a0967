#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Four-camera load test (the thesis's 360-degree case: four networks at once) through the real processes on LCM
# multicast in a private network namespace (it re-runs itself inside tools/netns_run.sh, as tools/fly.sh does).
# Each camera N is a wingman-camera-driver (--name camera_N) playing a 1280x720 30 fps clip (wingman make-video) from
# its file source in a loop, paced by the wall clock, on IMAGE_CAM<N> with camera_id N; a wingman-detector
# (--name detector_N, the shipped model builtin:wingman-small) detects in it; a wingman-localizer (--name
# localizer_N: it handles one camera id, so one per chain, each with its camera's extrinsics, yawed by 90 degrees
# per camera) tracks on TARGETS_CAM<N>; one wingman-follower-ctrl follows camera 0's targets (it reads one channel).
# lcm-logger records every channel but the images; tools/load_summary.py computes the figures and checks.
#
# Usage: tools/load_test.sh [--mode realtime|replay] [--duration S] [--out DIR] [--cameras N]
#                           [--soak] [--warmup S] [--sample-period S] [--replay-frames N] [--max-p99-s S]
#                           [--max-rss-growth-pct P] [--report-only]
#   --mode           realtime (default): cameras paced at 30 fps, detectors keep the newest frame when busy
#                    (input.mode realtime, drops counted); checks that every frame a detector received is processed
#                    or counted as dropped (at most one in flight at the end), that frames lost on the bus (published
#                    by the camera, never received: the detector cannot count them) stay under 20 % and are matched
#                    by kernel receive-buffer drops, that the end-to-end p99 stays below --max-p99-s and that the p50
#                    does not grow from the first half to the second.
#                    replay: the cameras write --replay-frames frames each into one LCM log (fast mode, fixed
#                    timestamps); four detectors in input.mode replay read it file to file
#                    (--lcm-in file://...?speed=0 --lcm-out file://...?mode=w); checks that every image got its
#                    detections_t (none lost, none duplicated). The input log is deleted after a passing run.
#   --duration       realtime: seconds the cameras play (default 30; with --soak 600)
#   --out            output folder (default build/load/MODE, build/load/soak with --soak)
#   --cameras        number of camera chains, 1..4 (default 4)
#   --soak           realtime, and also sample every process's RSS; fails if any process's RSS grows by more than
#                    --max-rss-growth-pct after --warmup (peak over the first third after the warm-up vs peak over
#                    the last third: single samples swing by an image buffer or two); prints the latency trend
#                    (first vs last third)
#   --warmup         soak: seconds after the cameras start before RSS is taken as the reference (default 30 for runs
#                    up to 180 s, else 60): model loading, OpenCL kernel builds, the first inference's buffers, LCM's
#                    receive buffers growing to a 2.7 MB image and glibc raising its mmap threshold to that size
#                    (after which image buffers come from the heap) all happen in the first seconds
#   --sample-period  seconds between RSS/CPU samples from /proc (default 2)
#   --replay-frames  replay: frames per camera (default 10; each 1280x720 BGR frame is 2.7 MB in the log)
#   --max-p99-s      realtime: bound on the end-to-end p99, seconds (default 5)
#   --max-rss-growth-pct  soak: bound on RSS growth after the warm-up, percent (default 5)
#   --report-only    the speed and memory bounds (p99, latency growth, RSS growth) are reported, not checked; the
#                    frame accounting and the processes' statuses stay checks (CI's load tests: speed and memory are
#                    not asserted in timed tests on a shared machine; docs/benchmarks.md, docs/reliability.md)
# Environment: WINGMAN_BIN_DIR (default build/bin).
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
bin="${WINGMAN_BIN_DIR:-$src/build/bin}"

mode=realtime duration="" out="" cameras=4 soak=false warmup="" sample_period=2 replay_frames=10 max_p99_s=5
max_rss_growth_pct=5 report_only=()
args=("$@")
while [ $# -gt 0 ]; do
  case "$1" in
    --mode) mode="$2"; shift 2 ;;
    --duration) duration="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --cameras) cameras="$2"; shift 2 ;;
    --soak) soak=true; shift ;;
    --warmup) warmup="$2"; shift 2 ;;
    --sample-period) sample_period="$2"; shift 2 ;;
    --replay-frames) replay_frames="$2"; shift 2 ;;
    --max-p99-s) max_p99_s="$2"; shift 2 ;;
    --max-rss-growth-pct) max_rss_growth_pct="$2"; shift 2 ;;
    --report-only) report_only=(--report-only); shift ;;
    -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "load_test: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
die() { echo "load_test: $1" >&2; exit 2; }
case "$mode" in realtime|replay) ;; *) die "--mode '$mode': expected realtime or replay" ;; esac
[ "$soak" = true ] && [ "$mode" = replay ] && die "--soak runs in realtime mode; drop --mode replay"
case "$cameras" in 1|2|3|4) ;; *) die "--cameras '$cameras': expected 1..4" ;; esac
isnum() { [[ "$1" =~ ^[0-9]+([.][0-9]+)?$ ]]; }
duration="${duration:-$([ "$soak" = true ] && echo 600 || echo 30)}"
isnum "$duration" || die "--duration '$duration': expected seconds"
if [ -z "$warmup" ]; then warmup=$(awk -v d="$duration" 'BEGIN{print (d <= 180 ? 30 : 60)}'); fi
for v in "$warmup" "$sample_period" "$max_p99_s" "$max_rss_growth_pct"; do
  isnum "$v" || die "'$v': expected a number"
done
[[ "$replay_frames" =~ ^[1-9][0-9]*$ ]] || die "--replay-frames '$replay_frames': expected a positive integer"
if [ "$soak" = true ] && awk -v d="$duration" -v w="$warmup" 'BEGIN{exit !(d < w + 20)}'; then
  die "--duration $duration: a soak needs at least the warm-up ($warmup s) plus 20 s"
fi
out="${out:-$src/build/load/$([ "$soak" = true ] && echo soak || echo "$mode")}"
for exe in wingman-camera-driver wingman-detector wingman-localizer wingman-follower-ctrl wingman; do
  [ -x "$bin/$exe" ] || die "$bin/$exe is missing: build first (tools/build.sh)"
done
command -v lcm-logger >/dev/null || die "lcm-logger is missing (tools/install_deps.sh)"
# load_summary.py decodes with the generated Python types: the build tree's (build/python beside the binaries) or an
# installed prefix's; checked now, not after the run.
pypath="$(dirname "$bin")/python:$(dirname "$bin")/lib/python3/dist-packages${PYTHONPATH:+:$PYTHONPATH}"
summary=(env PYENV_VERSION=system "PYTHONPATH=$pypath" python3 "$src/tools/load_summary.py")
"${summary[@]}" --help > /dev/null || die "tools/load_summary.py cannot run (above)"

if [ "${WINGMAN_IN_NETNS:-}" != "1" ]; then
  exec tools/netns_run.sh "$0" "${args[@]}"
fi
export PYENV_VERSION=system POCL_AFFINITY="${POCL_AFFINITY:-1}" OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}" \
  OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}"
mkdir -p "$out"
out=$(realpath "$out")
url="$WINGMAN_LCM_URL"

clip="$out/clip_1280x720.avi"
if [ ! -s "$clip" ]; then
  "$bin/wingman" make-video "$clip.tmp.avi" --width 1280 --height 720 --frames 90 --fps 30 > "$out/make_video.log" 2>&1 ||
    { cat "$out/make_video.log" >&2; echo "load_test: FAILED: wingman make-video" >&2; exit 1; }
  mv "$clip.tmp.avi" "$clip"
fi

# Camera i looks along body x yawed by 90 degrees * i (FLU): camera optical frame -> body, row-major.
extrinsics=("0, 0, 1, -1, 0, 0, 0, -1, 0" "1, 0, 0, 0, 0, 1, 0, -1, 0" "0, 0, -1, 1, 0, 0, 0, -1, 0"
            "-1, 0, 0, 0, 0, -1, 0, -1, 0")
# Each process: its defaults with these keys over them (--set, read by its config loader, as in tools/fly.sh).
detector_sets() {  # detector_sets I: camera I's detector, the shipped model
  sets=(--set "input={channel: IMAGE_CAM$1, mode: $mode}" --set "output.channel=DETECTIONS_CAM$1"
        --set 'model={cfg: "builtin:wingman-small", weights: "builtin:wingman-small"}')
}
localizer_sets() {  # localizer_sets I: camera I's localizer (one camera id per localizer), with its extrinsics
  sets=(--set "input.detections_channel=DETECTIONS_CAM$1" --set "output.channel=TARGETS_CAM$1"
        --set "camera.camera_id=$1" --set "extrinsics.R_cam_to_body=[${extrinsics[$1]}]")
}
# The follower follows camera 0's targets (it reads one targets channel).
follower_sets=(--set "input={targets_channel: TARGETS_CAM0, detections_channel: DETECTIONS_CAM0}")
camera_sets() {  # camera_sets I realtime|fast: camera I plays the clip in a loop at 30 fps
  sets=(--set "source.kind=file" --set "output={channel: IMAGE_CAM$1, camera_id: $1}"
        --set "file={path: \"$clip\", mode: $2, fps: 30.0, loop: true}")
  # fast: the replay log's frames, stamped from a fixed start time (deterministic); realtime: by the wall clock.
  [ "$2" = realtime ] || sets+=(--set file.start_utime=1700000000000000 --set "output.max_frames=$replay_frames")
}
# Every process's merged configuration, as its loader read it (a record of the run).
record_config() {  # record_config FILE EXE SETS...
  local file=$1 exe=$2; shift 2
  "$bin/$exe" "$@" --print-config > "$file" || { echo "load_test: FAILED: $exe rejects its settings (above)" >&2; exit 1; }
}
for ((i = 0; i < cameras; i++)); do
  detector_sets "$i"; record_config "$out/detector_$i.yaml" wingman-detector "${sets[@]}"
  localizer_sets "$i"; record_config "$out/localizer_$i.yaml" wingman-localizer "${sets[@]}"
  camera_sets "$i" "$([ "$mode" = replay ] && echo fast || echo realtime)"
  record_config "$out/camera_$i.yaml" wingman-camera-driver "${sets[@]}"
done
record_config "$out/follower_ctrl.yaml" wingman-follower-ctrl "${follower_sets[@]}"

# ---------------------------------------------------------------------------------------------------- replay
if [ "$mode" = replay ]; then
  images="$out/images.lcmlog"
  rm -f "$images" "$out"/detections_*.lcmlog
  # The same four-camera input as real time, recorded: each camera in turn appends its frames to one log, stamped
  # from a fixed start time (fast mode: deterministic), as the cameras would have captured them together.
  for ((i = 0; i < cameras; i++)); do
    camera_sets "$i" fast
    "$bin/wingman-camera-driver" --name "camera_$i" "${sets[@]}" --log-level warn \
      --lcm-out "file://$images?mode=$([ "$i" = 0 ] && echo w || echo a)"
  done
  echo "load_test: replay: $cameras cameras x $replay_frames frames of 1280x720 BGR in $images" \
       "($(du -m "$images" | cut -f1) MiB); $cameras detectors read it file to file, in parallel"
  SECONDS=0
  pids=()
  for ((i = 0; i < cameras; i++)); do
    detector_sets "$i"
    "$bin/wingman-detector" --name "detector_$i" "${sets[@]}" --log-level warn \
      --lcm-in "file://$images?speed=0" --lcm-out "file://$out/detections_$i.lcmlog?mode=w" & pids+=($!)
  done
  rc=0
  for p in "${pids[@]}"; do wait "$p" || rc=1; done
  echo "load_test: replay: detectors done in $SECONDS s"
  [ "$rc" = 0 ] || { echo "load_test: FAILED: a detector exited non-zero" >&2; exit 1; }
  rc=0
  "${summary[@]}" replay "$images" "$out"/detections_*.lcmlog --json "$out/summary.json" || rc=1
  # The input log is large and made anew by every run: kept only when a check failed.
  [ "$rc" = 0 ] && rm -f "$images"
  exit "$rc"
fi

# -------------------------------------------------------------------------------------------------- realtime
log="$out/load.lcmlog" proc_csv="$out/processes.csv"
rm -f "$log" "$proc_csv"
declare -A pid_of=()
names=() logger_pid="" sampler_pid=""
stop() {  # stop NAME...: SIGTERM, then wait for each
  local n
  for n in "$@"; do [ -n "${pid_of[$n]:-}" ] && kill -TERM "${pid_of[$n]}" 2>/dev/null || true; done
  for n in "$@"; do [ -n "${pid_of[$n]:-}" ] && { wait "${pid_of[$n]}" 2>/dev/null || true; unset "pid_of[$n]"; }; done
}
cleanup() {
  [ -n "$sampler_pid" ] && { kill -TERM "$sampler_pid" 2>/dev/null || true; wait "$sampler_pid" 2>/dev/null || true; }
  sampler_pid=""
  stop "${!pid_of[@]}"
  [ -n "$logger_pid" ] && { kill -TERM "$logger_pid" 2>/dev/null || true; wait "$logger_pid" 2>/dev/null || true; }
  logger_pid=""
}
trap cleanup EXIT
exited() { echo "load_test: FAILED: $1 exited $2; its stderr:" >&2; tail -5 "$out/$1.stderr" >&2; exit 1; }
start() {  # start NAME EXE ARGS...
  local name="$1" exe="$2"; shift 2
  "$bin/$exe" --name "$name" --lcm-url "$url" --log-level info "$@" 2> "$out/$name.stderr" &
  pid_of[$name]=$!
  names+=("$name")
}

echo "load_test: $cameras cameras x 1280x720 x 30 fps for $duration s on $url (private network namespace), output in $out"
lcm-logger --lcm-url="$url" --force --quiet --channel='IMAGE_.*' --invert-channels "$log" & logger_pid=$!
for ((i = 0; i < cameras; i++)); do
  detector_sets "$i"; start "detector_$i" wingman-detector "${sets[@]}"
  localizer_sets "$i"; start "localizer_$i" wingman-localizer "${sets[@]}"
done
start follower_ctrl wingman-follower-ctrl "${follower_sets[@]}"
# Start-up takes seconds (each detector loads the model and picks its backend): wait, at most 180 s, until every
# process has published its first heartbeat, which it does once it listens.
ready=false
for _ in $(seq 360); do
  info=$("$bin/wingman" loginfo "$log" 2>/dev/null || true)
  ready=true
  for n in "${names[@]}"; do grep -q "^STATUS_${n^^} " <<<"$info" || { ready=false; break; }; done
  [ "$ready" = true ] && break
  for n in "${names[@]}"; do kill -0 "${pid_of[$n]}" 2>/dev/null || exited "$n" "during start-up"; done
  sleep 0.5
done
[ "$ready" = true ] || { echo "load_test: FAILED: not every process reported within 180 s" >&2; exit 1; }

# Samples every process's RSS (VmRSS) and CPU time (utime + stime, all threads) from /proc into the CSV: one awk per
# pass, so the sampler itself costs little.
tck=$(getconf CLK_TCK)
sampler() {
  local t0 list=() n
  t0=$(date +%s.%N)
  for n in "${!pid_of[@]}"; do list+=("$n" "${pid_of[$n]}"); done
  echo "t_s,process,pid,rss_kib,cpu_s" > "$proc_csv"
  while true; do
    awk -v t0="$t0" -v now="$(date +%s.%N)" -v tck="$tck" 'BEGIN {
      for (i = 1; i < ARGC; i += 2) {
        name = ARGV[i]; pid = ARGV[i + 1]; rss = ""; stat = ""
        while ((getline line < ("/proc/" pid "/status")) > 0) if (line ~ /^VmRSS:/) { split(line, f); rss = f[2] }
        close("/proc/" pid "/status")
        if ((getline stat < ("/proc/" pid "/stat")) > 0) {
          sub(/.*\) /, "", stat); split(stat, f)
          if (rss != "") printf "%.2f,%s,%s,%s,%.2f\n", now - t0, name, pid, rss, (f[12] + f[13]) / tck
        }
        close("/proc/" pid "/stat")
      } }' "${list[@]}" >> "$proc_csv"
    sleep "$sample_period"
  done
}

for ((i = 0; i < cameras; i++)); do camera_sets "$i" realtime; start "camera_$i" wingman-camera-driver "${sets[@]}"; done
sampler & sampler_pid=$!
echo "load_test: pipeline up; cameras playing"
SECONDS=0
end=$(awk -v d="$duration" 'BEGIN{print int(d + 0.999)}')
while [ "$SECONDS" -lt "$end" ]; do
  for n in "${names[@]}"; do
    kill -0 "${pid_of[$n]}" 2>/dev/null || exited "$n" "during the run"
  done
  sleep 1
done
kill -TERM "$sampler_pid" 2>/dev/null || true; wait "$sampler_pid" 2>/dev/null || true; sampler_pid=""
# Stop the sources first, give the detectors time to finish the frame in hand, then the rest (each publishes a
# final STOPPING heartbeat with its counts), then the logger.
cams=() rest=()
for n in "${names[@]}"; do case "$n" in camera_*) cams+=("$n") ;; *) rest+=("$n") ;; esac; done
stop "${cams[@]}"
sleep 3
stop "${rest[@]}"
sleep 0.5
kill -TERM "$logger_pid" 2>/dev/null || true; wait "$logger_pid" 2>/dev/null || true; logger_pid=""
trap - EXIT
# The namespace is ours alone: its UDP counters are this run's. RcvbufErrors: datagrams the kernel dropped because a
# socket's receive buffer was full (a reader that did not keep up), the only way a published frame is lost here.
udp_counter() {
  awk -v k="$1" '/^Udp:/ { if (!h) { for (i = 1; i <= NF; i++) c[$i] = i; h = 1 } else print $c[k] }' /proc/net/snmp
}
rcvbuf_errors=$(udp_counter RcvbufErrors)
echo "load_test: UDP in this namespace: $(udp_counter InDatagrams) datagrams received," \
     "$rcvbuf_errors dropped on full receive buffers"
for n in "${names[@]}"; do
  grep -h "backend" "$out/$n.stderr" 2>/dev/null | sed "s/^/load_test: $n: /" | head -1 || true
  grep -E "\] (warning|error|critical):" "$out/$n.stderr" 2>/dev/null | sed "s/^/load_test: $n: /" | head -3 || true
done

echo
rc=0
"${summary[@]}" realtime "$log" --cameras "$cameras" --proc-csv "$proc_csv" --max-p99-s "$max_p99_s" \
  --udp-rcvbuf-errors "$rcvbuf_errors" "${report_only[@]}" --json "$out/summary.json" || rc=1
if [ "$soak" = true ]; then
  echo
  "${summary[@]}" soak "$log" --proc-csv "$proc_csv" --warmup-s "$warmup" --max-rss-growth-pct "$max_rss_growth_pct" \
    "${report_only[@]}" --json "$out/soak.json" || rc=1
fi
echo "load_test: log $log, samples $proc_csv, figures $out/summary.json"
exit "$rc"

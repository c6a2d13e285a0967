#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Renders config/supervisor/wingman.conf (written for the installed layout) for a build tree or any other layout:
# the same file with its paths, LCM URL and log folder substituted, so what runs is what ships (its stopped-process
# listener, installed in share/wingman/supervisor, runs from config/supervisor of this checkout).
#
# Usage: tools/supervise.sh [--bin DIR] [--etc DIR] [--log-dir DIR] [--lcm-url URL] [--out FILE]
#                           [--standalone DIR]
#   --bin         folder of the executables (default: build/bin of this checkout; installed: /usr/local/bin)
#   --etc         folder of the process configurations camera_driver.yaml, detector.yaml, localizer.yaml,
#                 follower_ctrl.yaml, mavlink_bridge.yaml, recorder.yaml (default: config/ of this checkout; installed: /usr/local/etc/wingman)
#   --log-dir     folder of the processes' logs and the recorder's recordings/ (created; default:
#                 build/supervisor/log; installed: /var/log/supervisor and /var/log/wingman/recordings)
#   --lcm-url     LCM URL of the bus (default: the file's, udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304)
#   --out         write the rendered program file here (default: stdout, or DIR/wingman.conf with --standalone)
#   --standalone  also write DIR/supervisord.conf: a supervisord that runs without root, with its socket, pid file
#                 and logs in DIR and the rendered wingman.conf included. Run it with
#                 `supervisord -n -c DIR/supervisord.conf`, control it with `supervisorctl -c DIR/supervisord.conf`.
# Example (a build tree, in a private network namespace):
#   tools/supervise.sh --standalone /tmp/wm && tools/netns_run.sh supervisord -n -c /tmp/wm/supervisord.conf
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
bin="$src/build/bin" etc="$src/config" log_dir="" url="" out="" standalone=""
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --etc) etc="$2"; shift 2 ;;
    --log-dir) log_dir="$2"; shift 2 ;;
    --lcm-url) url="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --standalone) standalone="$2"; shift 2 ;;
    -h|--help) sed -n '3,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "supervise: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
template="$src/config/supervisor/wingman.conf"
[ -r "$template" ] || { echo "supervise: cannot read $template" >&2; exit 2; }
for exe in wingman-camera-driver wingman-detector wingman-localizer wingman-follower-ctrl wingman-mavlink wingman-recorder; do
  [ -x "$bin/$exe" ] || { echo "supervise: --bin $bin: no executable $exe (build first: tools/build.sh)" >&2; exit 2; }
done
for cfg in camera_driver detector localizer follower_ctrl mavlink_bridge recorder; do
  [ -r "$etc/$cfg.yaml" ] || { echo "supervise: --etc $etc: cannot read $cfg.yaml" >&2; exit 2; }
done
if [ -n "$standalone" ]; then
  mkdir -p "$standalone"
  standalone=$(cd "$standalone" && pwd)
  out="${out:-$standalone/wingman.conf}"
fi
[ -n "$log_dir" ] || log_dir="${standalone:+$standalone/log}"
[ -n "$log_dir" ] || log_dir="$src/build/supervisor/log"
mkdir -p "$log_dir/recordings"  # the recorder's output.directory (recordings) is relative to it
bin=$(cd "$bin" && pwd) etc=$(cd "$etc" && pwd) log_dir=$(cd "$log_dir" && pwd)
case "$url" in *%*|*'"'*|*,*) echo "supervise: --lcm-url '$url': %, \" and , cannot be written into a supervisord environment" >&2; exit 2 ;; esac

# The one renderer of the shipped files (cmake/wingman_render.cmake, also `cmake --install`'s), run by CMake.
command -v cmake > /dev/null || { echo "supervise: cmake is missing (tools/install_deps.sh)" >&2; exit 2; }
target="$out"
[ -n "$target" ] || target=$(mktemp)
cmake -DSOURCE_DIR="$src" -DOUT="$target" -DBIN="$bin" -DETC="$etc" -DLOG_DIR="$log_dir" -DLCM_URL="$url" \
  -DSTANDALONE="$standalone" -P "$src/cmake/render_tree.cmake"
if [ -z "$out" ]; then cat "$target"; rm -f "$target"; fi

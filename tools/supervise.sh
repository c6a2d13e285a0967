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

# Paths are substituted literally (sed with | as the delimiter: none of these may contain |).
for p in "$bin" "$etc" "$log_dir" "$url"; do
  case "$p" in *'|'*) echo "supervise: '$p': a path or URL with | cannot be substituted" >&2; exit 2 ;; esac
done
esc() { printf '%s' "$1" | sed 's/[&\\]/\\&/g'; }
render() {
  sed -e "s|/usr/local/bin/|$(esc "$bin")/|g" \
      -e "s|/usr/local/etc/wingman/|$(esc "$etc")/|g" \
      -e "s|/var/log/wingman/|$(esc "$log_dir")/|g" \
      -e "s|/var/log/supervisor/|$(esc "$log_dir")/|g" \
      -e "s|/usr/local/share/wingman/supervisor/|$(esc "$src/config/supervisor")/|g" \
      ${url:+-e "s|udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304|$(esc "$url")|g"} \
      "$template"
}
if [ -n "$out" ]; then render > "$out"; else render; fi

if [ -n "$standalone" ]; then
  cat > "$standalone/supervisord.conf" <<CONF
; Written by tools/supervise.sh: a supervisord of its own (no root), running $out.
[unix_http_server]
file=$standalone/supervisor.sock
chmod=0700

[supervisord]
nodaemon=true
logfile=$standalone/supervisord.log
pidfile=$standalone/supervisord.pid
childlogdir=$log_dir
loglevel=info

[rpcinterface:supervisor]
supervisor.rpcinterface_factory = supervisor.rpcinterface:make_main_rpcinterface

[supervisorctl]
serverurl=unix://$standalone/supervisor.sock

[include]
files=$out
CONF
fi

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Screenshot of `wingman spy` on a virtual X display, fed with one sample of every message type (in a private netns).
#
# Usage: tools/spy_screenshot.sh OUT.png
# Environment:
#   WINGMAN_BIN_DIR          directory of the `wingman` binary (default: build/bin)
#   WINGMAN_PUBLISH_SAMPLES  wingman-publish-samples (default: WINGMAN_BIN_DIR/../tests/wingman-publish-samples)
#   SPY_SCREEN               Xvfb screen, WIDTHxHEIGHTxDEPTH (default: 1280x800x24)
#   SPY_PUBLISH_S            seconds to publish before the screenshot (default: 4)
# Exits 0 with OUT.png written; 1 when spy died, its window never appeared, or the screenshot is blank;
# 2 on a usage error or a missing program.
set -euo pipefail

script_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo_dir="$(dirname "$script_dir")"

if [ $# -ne 1 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
  sed -n '3,12p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  [ $# -eq 1 ] && exit 0 || exit 2
fi

# Never multicast on the host: re-run inside a private network namespace (loopback multicast only).
if [ "${WINGMAN_IN_NETNS:-}" != "1" ]; then
  exec "$script_dir/netns_run.sh" "${BASH_SOURCE[0]}" "$@"
fi

out_png="$(realpath -m "$1")"
bin_dir="${WINGMAN_BIN_DIR:-$repo_dir/build/bin}"
publish="${WINGMAN_PUBLISH_SAMPLES:-$bin_dir/../tests/wingman-publish-samples}"
screen="${SPY_SCREEN:-1280x800x24}"
publish_s="${SPY_PUBLISH_S:-4}"
url="${WINGMAN_LCM_URL:?netns_run.sh exports WINGMAN_LCM_URL}"

for prog in Xvfb xwd xwdtopnm pnmtopng ppmhist xwininfo "$bin_dir/wingman" "$publish"; do
  if ! command -v "$prog" >/dev/null 2>&1; then
    echo "spy_screenshot: error: $prog not found (build the project; Debian: xvfb x11-apps x11-utils netpbm)" >&2
    exit 2
  fi
done
mkdir -p "$(dirname "$out_png")"

work="$(mktemp -d "${TMPDIR:-/tmp}/wingman_spy_screenshot.XXXXXX")"
xvfb_pid=""
spy_pid=""
pub_pid=""

# Sends SIGTERM to a process, waits up to 5 s, then SIGKILL.
stop_process() {
  local pid="$1"
  [ -n "$pid" ] || return 0
  kill -TERM "$pid" 2>/dev/null || return 0
  for _ in $(seq 50); do
    kill -0 "$pid" 2>/dev/null || { wait "$pid" 2>/dev/null || true; return 0; }
    sleep 0.1
  done
  echo "spy_screenshot: pid $pid ignored SIGTERM for 5 s; killing it" >&2
  kill -KILL "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}

cleanup() {
  stop_process "$pub_pid"
  stop_process "$spy_pid"
  stop_process "$xvfb_pid"
  rm -rf "$work"
}
trap cleanup EXIT

fail() {
  echo "spy_screenshot: FAILED: $*" >&2
  if [ -n "$xvfb_pid" ]; then
    kill -0 "$xvfb_pid" 2>/dev/null && echo "spy_screenshot: Xvfb (pid $xvfb_pid) is running" >&2 ||
      echo "spy_screenshot: Xvfb (pid $xvfb_pid) has exited" >&2
  fi
  # A Java exception's message is its first line and the stack follows: show both ends of a long log.
  for f in spy.log xvfb.log publish.log; do
    if [ -s "$work/$f" ]; then
      if [ "$(wc -l <"$work/$f")" -le 40 ]; then
        echo "---- $f ----" >&2
        cat "$work/$f" >&2
      else
        echo "---- $f (first 10 and last 20 lines) ----" >&2
        head -n 10 "$work/$f" >&2
        echo "[...]" >&2
        tail -n 20 "$work/$f" >&2
      fi
    fi
  done
  exit 1
}

# Xvfb picks a free display itself and writes its number, then a newline, to fd 3 (two writes: a number read before
# its newline may be cut short, e.g. 1 of 10).
Xvfb -displayfd 3 -screen 0 "$screen" -nolisten tcp 3>"$work/display" >"$work/xvfb.log" 2>&1 &
xvfb_pid=$!
display_complete() { [ -s "$work/display" ] && [ "$(tail -c 1 "$work/display" | od -An -c | tr -d ' ')" = '\n' ]; }
for _ in $(seq 100); do
  display_complete && break
  kill -0 "$xvfb_pid" 2>/dev/null || fail "Xvfb exited"
  sleep 0.1
done
display_complete || fail "Xvfb did not report a display within 10 s"
DISPLAY=":$(tr -d '[:space:]' <"$work/display")"
export DISPLAY
# The server must answer a client before Java's toolkit connects: Java gives up at its first failed connection.
for _ in $(seq 100); do
  xwininfo -root >/dev/null 2>&1 && break
  kill -0 "$xvfb_pid" 2>/dev/null || fail "Xvfb exited after reporting $DISPLAY"
  sleep 0.1
done
xwininfo -root >/dev/null 2>&1 || fail "Xvfb on $DISPLAY answered no client within 10 s"
echo "spy_screenshot: Xvfb on $DISPLAY ($screen), LCM $url"

"$bin_dir/wingman" spy --lcm-url "$url" >"$work/spy.log" 2>&1 &
spy_pid=$!

# Wait (at most 20 s) for lcm-spy's window.
for _ in $(seq 200); do
  kill -0 "$spy_pid" 2>/dev/null || fail "wingman spy exited before its window appeared"
  xwininfo -root -tree 2>/dev/null | grep -q '"LCM Spy"' && break
  sleep 0.1
done
xwininfo -root -tree 2>/dev/null | grep -q '"LCM Spy"' || fail "no \"LCM Spy\" window within 20 s"
# lcm-spy prints how many LCM types it found on its classpath; 0 means no channel can decode.
grep -Eq 'Found [1-9][0-9]* LCM types' "$work/spy.log" || fail "lcm-spy found no LCM types on its classpath"

# Publish every channel at 10 Hz in the background until the screenshot is taken.
"$publish" --lcm-url "$url" --repeat 100000 --period-ms 100 >"$work/publish.log" 2>&1 &
pub_pid=$!
sleep "$publish_s"
kill -0 "$pub_pid" 2>/dev/null || fail "wingman-publish-samples exited early"
kill -0 "$spy_pid" 2>/dev/null || fail "wingman spy died while receiving samples"

xwd -root -silent -display "$DISPLAY" >"$work/screen.xwd" || fail "xwd failed"
xwdtopnm <"$work/screen.xwd" 2>/dev/null >"$work/screen.ppm" || fail "xwdtopnm failed"
pnmtopng <"$work/screen.ppm" >"$out_png" 2>/dev/null || fail "pnmtopng failed"
colours="$(ppmhist -noheader "$work/screen.ppm" 2>/dev/null | wc -l)"
[ "$colours" -ge 3 ] || fail "screenshot is blank ($colours colours): $out_png"
kill -0 "$spy_pid" 2>/dev/null || fail "wingman spy died during the screenshot"

# wingman spy forwards SIGTERM to java; it must end promptly.
stop_process "$pub_pid"
pub_pid=""
kill -TERM "$spy_pid"
for _ in $(seq 100); do
  kill -0 "$spy_pid" 2>/dev/null || break
  sleep 0.1
done
kill -0 "$spy_pid" 2>/dev/null && fail "wingman spy still running 10 s after SIGTERM"
spy_rc=0
wait "$spy_pid" || spy_rc=$?
spy_pid=""
echo "spy_screenshot: OK: $out_png ($colours colours; wingman spy exited $spy_rc after SIGTERM)"

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Checks config/systemd/ with `systemd-analyze verify`: the units are rendered for the build tree (the executables'
# folder substituted for /usr/local/bin, as for an install there) and any warning or error fails the test. Also
# checks that each unit runs its process with its configuration, restarts it always, stops it with SIGTERM and
# that wingman.target wants all six, and that `systemd-analyze security --offline=true` rates each unit's sandbox at
# an overall exposure of at most 3.0 (printed per unit). Then the same two checks on the units as `cmake --install`
# renders them for --prefix /usr and --prefix /opt/wingman (cmake/install_layout.cmake run into a scratch root, the
# build's executables linked where the units name them, systemd's own units copied in; `--root=` makes systemd-analyze
# resolve every path there). Exits 77 (skipped) when systemd-analyze is not installed.
# Usage: tests/reliability/systemd_units_test.sh SRC_DIR BIN_DIR
set -euo pipefail
src=$(cd "$1" && pwd) bin=$(cd "$2" && pwd)
if ! command -v systemd-analyze > /dev/null; then
  echo "systemd_units_test: SKIPPED: systemd-analyze is not installed (Debian package systemd)"
  exit 77
fi
tmp=$(mktemp -d /tmp/wingman-systemd.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
declare -A cfg=([wingman-camera-driver]=camera_driver [wingman-detector]=detector [wingman-localizer]=localizer
                [wingman-follower-ctrl]=follower_ctrl [wingman-mavlink]=mavlink_bridge [wingman-recorder]=recorder)
for unit in "$src"/config/systemd/*; do sed "s|/usr/local/bin/|$bin/|g" "$unit" > "$tmp/$(basename "$unit")"; done
for exe in "${!cfg[@]}"; do
  u="$src/config/systemd/$exe.service"
  [ -r "$u" ] || { fail "no unit $u"; continue; }
  grep -qx "ExecStart=/usr/local/bin/$exe --config /usr/local/etc/wingman/${cfg[$exe]}.yaml" "$u" || fail "$u: ExecStart"
  for key in Type=notify NotifyAccess=main WatchdogSec=5 Restart=always KillSignal=SIGTERM TimeoutStopSec=2 RestartSec=0.5 WantedBy=wingman.target \
             PartOf=wingman.target; do
    grep -qx "$key" "$u" || fail "$u: no $key"
  done
  grep -q '^Environment="LCM_DEFAULT_URL=udpm://.*ttl=0&recv_buf_size=4194304"$' "$u" || fail "$u: no LCM URL"
  grep -q "^Wants=.*$exe.service" "$src/config/systemd/wingman.target" || fail "wingman.target does not want $exe"
done
# verify reads the units as systemd would load them; it prints every problem (unknown keys included) on stderr.
if ! systemd-analyze verify --man=no "$tmp"/wingman.target "$tmp"/wingman-*.service > "$tmp/verify.txt" 2>&1 ||
   [ -s "$tmp/verify.txt" ]; then
  fail "systemd-analyze verify:"; cat "$tmp/verify.txt"
fi
# The sandbox: "Overall exposure level for UNIT: N.N LABEL" (0 best, 10 worst; docs/reliability.md, "systemd").
max_exposure=3.0
for exe in $(printf '%s\n' "${!cfg[@]}" | sort); do
  [ -r "$tmp/$exe.service" ] || continue
  out=$(systemd-analyze security --offline=true --no-pager "$tmp/$exe.service" 2>&1) || true
  score=$(sed -nE "s/.*Overall exposure level for $exe\.service: ([0-9]+\.[0-9]+).*/\1/p" <<<"$out")
  if [ -z "$score" ]; then
    fail "$exe.service: no exposure level from systemd-analyze security:"; echo "$out" | tail -n 5
  elif awk -v s="$score" -v m="$max_exposure" 'BEGIN { exit !(s > m) }'; then
    fail "$exe.service: exposure $score > $max_exposure:"; grep '✗' <<<"$out" || true
  else
    echo "$exe.service: exposure $score (at most $max_exposure)"
  fi
done
# The installed units, per prefix: rendered by the install script into a scratch root.
for prefix in /usr /opt/wingman; do
  root="$tmp/root${prefix//\//-}"
  if ! DESTDIR="$root" cmake -DWINGMAN_SOURCE_DIR="$src" -DCMAKE_INSTALL_PREFIX="$prefix" \
       -P "$src/cmake/install_layout.cmake" > "$tmp/install.txt" 2>&1; then
    fail "--prefix $prefix: cmake/install_layout.cmake failed:"; cat "$tmp/install.txt"; continue
  fi
  mkdir -p "$root$prefix/bin" "$root/etc/systemd/system" "$root/usr/lib/systemd"
  # Hard links where the file system allows (the executables are tens of MB), copies otherwise; a symbolic link would
  # point outside the root.
  for exe in "${!cfg[@]}"; do ln -f "$bin/$exe" "$root$prefix/bin/$exe" 2> /dev/null || cp "$bin/$exe" "$root$prefix/bin/"; done
  cp -a /usr/lib/systemd/system "$root/usr/lib/systemd/"  # sysinit.target and the rest that units depend on
  cp "$root$prefix/share/wingman/systemd/"* "$root/etc/systemd/system/"
  if [ "$prefix" = /usr ]; then confdir=/etc/wingman; else confdir="/etc$prefix/wingman"; fi
  for exe in "${!cfg[@]}"; do
    grep -qx "ExecStart=$prefix/bin/$exe --config $confdir/${cfg[$exe]}.yaml" "$root/etc/systemd/system/$exe.service" ||
      fail "--prefix $prefix: $exe.service: $(grep ExecStart= "$root/etc/systemd/system/$exe.service")"
  done
  if ! (cd / && systemd-analyze verify --man=no --root="$root" "$root"/etc/systemd/system/wingman.target \
        "$root"/etc/systemd/system/wingman-*.service) > "$tmp/verify.txt" 2>&1 || [ -s "$tmp/verify.txt" ]; then
    fail "--prefix $prefix: systemd-analyze verify:"; cat "$tmp/verify.txt"
  fi
  scores=""
  for exe in $(printf '%s\n' "${!cfg[@]}" | sort); do
    out=$(systemd-analyze security --offline=true --no-pager --root="$root" "$exe.service" 2>&1) || true
    score=$(sed -nE "s/.*Overall exposure level for $exe\.service: ([0-9]+\.[0-9]+).*/\1/p" <<<"$out")
    if [ -z "$score" ] || awk -v s="$score" -v m="$max_exposure" 'BEGIN { exit !(s > m) }'; then
      fail "--prefix $prefix: $exe.service: exposure '${score:-none}' (at most $max_exposure):"; tail -n 5 <<<"$out"
    fi
    scores+=" ${exe#wingman-} ${score:-none}"
  done
  echo "--prefix $prefix: the rendered units verified; exposure:$scores (each at most $max_exposure)"
done
[ "$failures" -eq 0 ] || exit 1
echo "systemd_units_test: ${#cfg[@]} units and wingman.target verified, as in the source tree and as installed to /usr and /opt/wingman ($(systemd-analyze --version | head -n 1))"

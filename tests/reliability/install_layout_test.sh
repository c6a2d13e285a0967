#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Checks the installed layout that config/supervisor/wingman.conf and config/systemd/ are written for: installs the
# build into a temporary prefix (cmake --install) and checks that every command line of the shipped supervisor
# program file and systemd units names an installed executable and configuration (their /usr/local read as the
# prefix), that each installed process accepts its installed configuration (--print-config), and that the
# supervisor and systemd files are installed beside them. The supervisor file's event listener (the one command
# that is not a process with --config) must be installed where its command names it and answer supervisord's
# protocol (READY, then RESULT 2 OK to one TICK_5 event).
# Usage: tests/reliability/install_layout_test.sh SRC_DIR BUILD_DIR
set -euo pipefail
src=$(cd "$1" && pwd) build=$(cd "$2" && pwd)
prefix=$(mktemp -d /tmp/wingman-install.XXXXXX)
trap 'rm -rf "$prefix"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
cmake --install "$build" --prefix "$prefix" > "$prefix.log" 2>&1 || { cat "$prefix.log"; rm -f "$prefix.log"; exit 1; }
rm -f "$prefix.log"
[ -r "$prefix/share/wingman/supervisor/wingman.conf" ] || fail "share/wingman/supervisor/wingman.conf not installed"
[ -r "$prefix/share/wingman/systemd/wingman.target" ] || fail "share/wingman/systemd/wingman.target not installed"
# Every command of the shipped files: an installed executable with an installed configuration it accepts.
listener=$(grep -h '^command=.*wingman-stopped-watch' "$src/config/supervisor/wingman.conf" | sed 's/^command=//')
read -r interpreter script <<< "$listener"
script=${script/#\/usr\/local/$prefix}
if [ ! -x "$script" ]; then
  fail "$script: the stopped-process listener is not installed"
else
  payload="when:1 serial:1"
  reply=$(printf 'ver:3.0 server:supervisor serial:1 pool:wingman-stopped-watch poolserial:1 eventname:TICK_5 len:%d\n%s' \
            "${#payload}" "$payload" | timeout 10 "$interpreter" "$script" 2>&1 || true)
  [ "$reply" = $'READY\nRESULT 2\nOKREADY' ] || fail "$interpreter $script: unexpected reply to one TICK_5 event: '$reply'"
fi
commands=$( (grep -h '^command=' "$src/config/supervisor/wingman.conf" | grep -v wingman-stopped-watch | sed 's/^command=//'
             grep -h '^ExecStart=' "$src"/config/systemd/*.service | sed 's/^ExecStart=//') | sort -u)
n=0
while read -r exe flag cfg rest; do
  [ -n "$exe" ] || continue
  exe=${exe/#\/usr\/local/$prefix} cfg=${cfg/#\/usr\/local/$prefix}
  [ "$flag" = --config ] || { fail "$exe: expected '--config FILE' in the command, got '$flag'"; continue; }
  [ -x "$exe" ] || { fail "$exe: not installed"; continue; }
  [ -r "$cfg" ] || { fail "$cfg: not installed"; continue; }
  # The rest of the command line (supervisord: --watchdog 5) must be accepted too.
  read -r -a more <<< "${rest:-}"
  if ! out=$("$exe" --config "$cfg" "${more[@]}" --print-config 2>&1); then
    fail "$exe --config $cfg ${rest:-} --print-config: $out"
  fi
  n=$((n + 1))
done <<< "$commands"
[ "$n" -ge 5 ] || fail "expected the commands of 5 processes, checked $n"
[ "$failures" -eq 0 ] || exit 1
echo "install_layout_test: $n process commands of the supervisor and systemd files run from an install in $prefix"

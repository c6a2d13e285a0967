#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Install anywhere (issue 34): installs the build twice (cmake --install with DESTDIR), for the prefixes /usr and
# /opt/wingman, and checks for each that the supervisor program file and the systemd units were rendered for that
# prefix (cmake/install_layout.cmake: no /usr/local path left in a command), that every command in them names an
# installed executable and configuration (read under DESTDIR) which the executable accepts (--print-config, with the
# rest of the command line), that the configurations are where the GNU rules put them (/etc/wingman for /usr,
# /etc/opt/wingman/wingman for /opt/wingman) and equal the shipped config/*.yaml, that the recorder's recordings
# folder was created, and that supervisord parses the installed file without a log folder of its own (a missing
# one would stop supervisord, and everything else it runs, from starting: checked on a copy that names one). The
# stopped-process listener must be installed where its command names it and answer supervisord's protocol. The
# installed `wingman train` runs the wingman-train installed beside it.
# Usage: tests/reliability/install_layout_test.sh SRC_DIR BUILD_DIR
set -euo pipefail
src=$(cd "$1" && pwd) build=$(cd "$2" && pwd)
root=$(mktemp -d /tmp/wingman-install.XXXXXX)
trap 'rm -rf "$root"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
py() { PYENV_VERSION=system python3 "$@"; }
# supervisord's own parser on a supervisord.conf that includes FILE: exit 0 when it would start.
supervisord_parses() {
  printf '[supervisord]\nlogfile=%s/sd.log\npidfile=%s/sd.pid\n[include]\nfiles=%s\n' "$root" "$root" "$1" > "$root/sd.conf"
  py -c 'import sys
from supervisor.options import ServerOptions
o = ServerOptions()
o.realize(args=["-c", sys.argv[1]])
print(" ".join(p.name for g in o.process_group_configs for p in g.process_configs))' "$root/sd.conf"
}

check_prefix() {  # check_prefix PREFIX CONFDIR
  local prefix="$1" confdir="$2" dest="$root/dest${1//\//_}"
  if ! DESTDIR="$dest" cmake --install "$build" --prefix "$prefix" > "$dest.log" 2>&1; then
    cat "$dest.log"; fail "cmake --install --prefix $prefix"; return
  fi
  local share="$dest$prefix/share/wingman"
  local conf="$share/supervisor/wingman.conf"
  [ -r "$conf" ] || { fail "$prefix: share/wingman/supervisor/wingman.conf not installed"; return; }
  [ -r "$share/systemd/wingman.target" ] || fail "$prefix: share/wingman/systemd/wingman.target not installed"
  for cfg in camera_driver detector localizer follower_ctrl mavlink_bridge recorder; do
    cmp -s "$src/config/$cfg.yaml" "$dest$confdir/$cfg.yaml" ||
      fail "$prefix: $confdir/$cfg.yaml is not the shipped config/$cfg.yaml"
  done
  for rig in "$src"/config/rigs/*.yaml; do
    cmp -s "$rig" "$dest$confdir/rigs/$(basename "$rig")" ||
      fail "$prefix: $confdir/rigs/$(basename "$rig") is not the shipped config/rigs/$(basename "$rig")"
  done
  # `wingman train` starts the wingman-train installed beside wingman (tools/src/forwarded_verbs.cpp).
  local train_help
  if [ ! -x "$dest$prefix/bin/wingman-train" ]; then
    fail "$prefix: bin/wingman-train (what \`wingman train\` starts) is not installed"
  elif ! train_help=$("$dest$prefix/bin/wingman" train --help 2>&1) ||
    ! grep -q -- '--cfg TEXT REQUIRED' <<<"$train_help"; then
    fail "$prefix: the installed wingman train --help: $train_help"
  fi
  if [ "$prefix" != /usr/local ] && grep -hE '^(command|ExecStart|directory|WorkingDirectory)=.*/usr/local' "$conf" "$share"/systemd/*; then
    fail "$prefix: a /usr/local path left in the rendered files (above)"
  fi
  local listener interpreter script
  listener=$(grep -h '^command=.*wingman-stopped-watch' "$conf" | sed 's/^command=//')
  read -r interpreter script <<< "$listener"
  if [ ! -x "$dest$script" ]; then
    fail "$prefix: $script: the stopped-process listener is not installed"
  else
    local payload="when:1 serial:1" reply
    reply=$(printf 'ver:3.0 server:supervisor serial:1 pool:wingman-stopped-watch poolserial:1 eventname:TICK_5 len:%d\n%s' \
              "${#payload}" "$payload" | timeout 10 "$interpreter" "$dest$script" 2>&1 || true)
    [ "$reply" = $'READY\nRESULT 2\nOKREADY' ] || fail "$prefix: $interpreter $script: unexpected reply to one TICK_5 event: '$reply'"
  fi
  local recordings
  recordings=$(grep -h '^directory=' "$conf" | sed 's/^directory=//')
  [ -d "$dest$recordings/recordings" ] || fail "$prefix: the recorder's folder $recordings/recordings was not created"
  # Every process command of both files: an installed executable with an installed configuration it accepts.
  local commands n=0 exe flag cfg rest out
  commands=$( (grep -h '^command=' "$conf" | grep -v wingman-stopped-watch | sed 's/^command=//'
               grep -h '^ExecStart=' "$share"/systemd/*.service | sed 's/^ExecStart=//') | sort -u)
  while read -r exe flag cfg rest; do
    [ -n "$exe" ] || continue
    [ "$flag" = --config ] || { fail "$exe: expected '--config FILE' in the command, got '$flag'"; continue; }
    case "$exe$cfg" in "$prefix"/*"$confdir"/*) ;; *) fail "$prefix: '$exe --config $cfg' is not under $prefix and $confdir"; continue ;; esac
    [ -x "$dest$exe" ] || { fail "$dest$exe: not installed"; continue; }
    [ -r "$dest$cfg" ] || { fail "$dest$cfg: not installed"; continue; }
    read -r -a more <<< "${rest:-}"
    if ! out=$("$dest$exe" --config "$dest$cfg" "${more[@]}" --print-config 2>&1); then
      fail "$dest$exe --config $dest$cfg ${rest:-} --print-config: $out"
    fi
    n=$((n + 1))
  done <<< "$commands"
  [ "$n" -ge 6 ] || fail "$prefix: expected the commands of 6 processes, checked $n"
  # supervisord starts with the installed file as it is; a log folder that does not exist would stop it.
  local programs
  if ! programs=$(supervisord_parses "$conf" 2>&1); then
    fail "$prefix: supervisord does not parse the installed file: $programs"
  fi
  sed 's|^stdout_logfile=/var/log/supervisor/|stdout_logfile=/var/log/wingman-missing/|' "$conf" > "$root/missing.conf"
  if supervisord_parses "$root/missing.conf" > "$root/missing.out" 2>&1; then
    fail "the supervisord parse check passes a file whose log folder is missing"
  fi
  echo "install_layout_test: --prefix $prefix: $n process commands run from the install (configurations in $confdir);" \
       "supervisord parses it: $programs"
}

check_prefix /usr /etc/wingman
check_prefix /opt/wingman /etc/opt/wingman/wingman
[ "$failures" -eq 0 ] || exit 1

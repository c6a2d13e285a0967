#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `wingman train` runs in wingman-train, so that `wingman` starts without libtorch (docs/benchmarks.md).
# links:   `wingman` needs no libtorch library (its ELF NEEDED entries, and the whole closure ldd resolves).
# forward: `wingman train ARGS` replaces itself with the wingman-train beside it: the same arguments, standard streams
#          and process id, so the exit code and a signal are the child's; --help is the child's; a missing
#          wingman-train is named.
# Usage: forwarded_verb_test.sh links WINGMAN | forward WINGMAN WORK_DIR
set -euo pipefail
mode="$1" wingman="$2"
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}

if [ "$mode" = links ]; then
  needed=$(readelf -d "$wingman" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
  grep -qx 'libc\.so\.6' <<<"$needed" || fail "readelf found no NEEDED libc.so.6 in $wingman: '$needed'"
  if grep -E '^lib(torch|c10|caffe2)' <<<"$needed"; then fail "$wingman links libtorch (NEEDED, above)"; fi
  if command -v ldd > /dev/null; then
    if ldd "$wingman" | grep -E '^\s*lib(torch|c10|caffe2)'; then fail "$wingman loads libtorch (ldd, above)"; fi
  fi
  [ "$failures" -eq 0 ] && echo "links: $wingman needs $(wc -l <<<"$needed") libraries, none of libtorch's"
  exit $((failures > 0))
fi

[ "$mode" = forward ] || { echo "usage: $0 links WINGMAN | forward WINGMAN WORK_DIR" >&2; exit 2; }
mkdir -p "$3"
work=$(mktemp -d "$3/forward.XXXXXX")
trap 'rm -rf "$work"' EXIT

# The real wingman-train beside the built wingman.
help=$("$wingman" --help)
grep -qE '^  train +Train a Darknet \.cfg network' <<<"$help" || fail "wingman --help does not list train: $help"
rc=0
out=$("$wingman" train --help 2>&1) || rc=$?
[ "$rc" -eq 0 ] || fail "wingman train --help exits $rc: $out"
for line in "Usage: wingman train [OPTIONS]" "--cfg TEXT REQUIRED" "--batch INT=64" "--ema-decay"; do
  grep -qF -- "$line" <<<"$out" || fail "wingman train --help has no '$line': $out"
done
rc=0
err=$("$wingman" train --cfg x.cfg --data x --no-such-option 2>&1) || rc=$?
[ "$rc" -eq 2 ] || fail "wingman train --no-such-option exits $rc, not 2: $err"
grep -q '^wingman: error: .*--no-such-option' <<<"$err" || fail "wingman train --no-such-option: '$err'"
rc=0
err=$("$wingman" train --cfg "$work/none.cfg" --data "$work" 2>&1) || rc=$?
[ "$rc" -eq 1 ] || fail "wingman train with a missing .cfg exits $rc, not 1: $err"
grep -q '^wingman train: error: ' <<<"$err" || fail "wingman train with a missing .cfg: '$err'"

# A copy of wingman alone (a hard link where it can: /proc/self/exe names the link's folder).
mkdir "$work/bin"
ln "$wingman" "$work/bin/wingman" 2> /dev/null || cp "$wingman" "$work/bin/wingman"
rc=0
err=$("$work/bin/wingman" train --help 2>&1) || rc=$?
[ "$rc" -eq 1 ] || fail "wingman train without wingman-train exits $rc, not 1: $err"
grep -qF "wingman train: error: cannot start $work/bin/wingman-train (No such file or directory)" <<<"$err" ||
  fail "wingman train without wingman-train does not name it: '$err'"

# A stand-in wingman-train: prints its process id and arguments, copies its standard input, exits 7 (or kills
# itself with SIGTERM).
cat > "$work/bin/wingman-train" <<'SH'
#!/bin/sh
echo "$$" > "$(dirname "$0")/pid"
printf '[%s]' "$0" "$@"
echo
cat
[ "${FAKE_SIGNAL:-}" = 1 ] && kill -TERM $$
exit 7
SH
chmod +x "$work/bin/wingman-train"
rc=0
out=$(printf 'from stdin\n' | "$work/bin/wingman" train --cfg 'a b.cfg' '' --help 2> "$work/err") || rc=$?
[ "$rc" -eq 7 ] || fail "the forwarded verb's exit code 7 came back as $rc ($(cat "$work/err"))"
[ "$out" = "[$work/bin/wingman-train][train][--cfg][a b.cfg][][--help]"$'\n'"from stdin" ] ||
  fail "wingman-train was not given wingman's arguments and standard input: '$out'"
"$work/bin/wingman" train < /dev/null > /dev/null &
started=$!
rc=0
wait "$started" || rc=$?
[ "$rc" -eq 7 ] || fail "wingman train in the background exits $rc, not 7"
pid=$(cat "$work/bin/pid" 2> /dev/null || echo none)
[ "$pid" = "$started" ] || fail "wingman-train ran as process $pid, not as wingman's own $started (no exec)"
# (bash -c: its "Terminated" line is not this test's output)
rc=$(FAKE_SIGNAL=1 bash -c '"$1" train < /dev/null > /dev/null; echo $?' _ "$work/bin/wingman" 2> /dev/null)
[ "$rc" -eq 143 ] || fail "a wingman-train killed by SIGTERM: wingman's status $rc, not 143 (128 + 15)"

[ "$failures" -eq 0 ] && echo "forward: wingman train runs $(dirname "$wingman")/wingman-train in its own process"
exit $((failures > 0))

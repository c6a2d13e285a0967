#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The README's commands and the camera demo answer --help without building (issue #34): each script is copied into a
# scratch tree whose tools/build.sh fails, so a script that builds first fails this test.
# Usage: script_help_test.sh SOURCE_DIR
set -euo pipefail
src="$1"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/tools"
printf '#!/usr/bin/env bash\necho "build.sh must not run for --help" >&2\nexit 99\n' > "$tmp/tools/build.sh"
# demo.sh shows tools/fly.sh's help after its own: a stand-in that only prints.
printf '#!/usr/bin/env bash\necho "fly.sh help"\n' > "$tmp/tools/fly.sh"
chmod +x "$tmp/tools/build.sh" "$tmp/tools/fly.sh"
failures=0
for script in demo.sh demo_camera.sh test.sh; do
  cp "$src/tools/$script" "$tmp/tools/$script"
  for flag in --help -h; do
    if out=$("$tmp/tools/$script" "$flag" 2>&1) && grep -q "^# " <<<"$out"; then
      echo "ok: tools/$script $flag"
    else
      echo "FAIL: tools/$script $flag did not print its help with exit 0 without building:"; echo "$out"
      failures=$((failures + 1))
    fi
  done
done
exit $((failures > 0))

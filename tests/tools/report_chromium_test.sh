#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `wingman report` in headless Chromium: writes a synthetic flight log, renders its report to a PNG and dumps the DOM.
#
# Usage: report_chromium_test.sh WINGMAN WRITE_REPORT_FLIGHT OUT_DIR
# Passes when the page loads without console errors, the headline's six figures are above the charts, every chart
# <svg id=...> has data, every frame decodes as a thumbnail, the screenshot not blank. OUT_DIR keeps page, PNG, DOM.
# Exits 77 (skipped) when chromium is not installed (Debian: chromium; tools/install_deps.sh installs it).
set -euo pipefail

if [ $# -ne 3 ]; then sed -n '3,9p' "$0" | sed 's/^# \{0,1\}//'; exit 2; fi
wingman="$1" write_flight="$2" out="$3"
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
  echo "report_chromium: SKIPPED: chromium is not installed (apt-get install chromium)"
  exit 77
fi
for prog in pngtopnm ppmhist; do
  command -v "$prog" >/dev/null || { echo "report_chromium: error: $prog not found (Debian: netpbm)" >&2; exit 2; }
done

mkdir -p "$out"
out=$(realpath "$out")
work=$(mktemp -d "${TMPDIR:-/tmp}/wingman_report_chromium.XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "report_chromium: FAIL: $*" >&2; exit 1; }

"$write_flight" "$work/flight.lcmlog"
"$wingman" report "$work/flight.lcmlog" -o "$out/report.html" --quiet --title "Report browser test"
[ -s "$out/report.html" ] || fail "wingman report wrote no $out/report.html"

# No network for the browser: everything must be inline. A fresh profile each run.
chrome=("$browser" --headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking
        --disable-component-update --disable-sync --disable-extensions --user-data-dir="$work/profile"
        --enable-logging=stderr --v=0 --virtual-time-budget=5000)
rm -f "$out/report.png"
timeout 90 "${chrome[@]}" --window-size=1280,2400 --screenshot="$out/report.png" "file://$out/report.html" \
  >"$work/shot.out" 2>"$work/shot.err" || fail "chromium --screenshot exited $? ($(tail -n 3 "$work/shot.err"))"
timeout 90 "${chrome[@]}" --dump-dom "file://$out/report.html" >"$out/dom.html" 2>"$work/dom.err" ||
  fail "chromium --dump-dom exited $? ($(tail -n 3 "$work/dom.err"))"

# Console errors of the page (not the browser's own noise about D-Bus and the like).
if grep -hE 'Uncaught|:CONSOLE[:(]|Console' "$work/shot.err" "$work/dom.err"; then fail "console errors (above)"; fi

# The screenshot: a PNG, 1280 wide, and not blank (charts and frames give many colours).
[ -s "$out/report.png" ] || fail "no screenshot"
pngtopnm "$out/report.png" >"$work/shot.ppm" || fail "report.png is not a PNG"
read -r _ width height < <(head -c 64 "$work/shot.ppm" | tr -s ' \n' ' ' | cut -d' ' -f1-3)
{ [ "$width" = 1280 ] && [ "$height" = 2400 ]; } || fail "screenshot is ${width}x$height px, expected 1280x2400"
colours=$(ppmhist -noheader "$work/shot.ppm" | wc -l)
[ "$colours" -ge 50 ] || fail "screenshot has only $colours colours: blank?"

# The headline first: six figures before the first chart; the fixture has no formation target, so that one alone
# is "not measured".
dom=$(tr '\n' ' ' <"$out/dom.html")
head_at=$(grep -ob '<table id="headline"' <<<"$dom" | head -n1 | cut -d: -f1 || true)
svg_at=$(grep -ob '<svg ' <<<"$dom" | head -n1 | cut -d: -f1 || true)
[ -n "$head_at" ] || fail "no headline table in the DOM"
[ "$head_at" -lt "$svg_at" ] || fail "the headline is not above the charts"
rows=$(grep -o '<tr data-key="[a-z_]*" data-measured="[01]"' <<<"$dom" | wc -l)
[ "$rows" = 6 ] || fail "$rows headline figures, expected 6"
unmeasured=$(grep -o 'data-key="[a-z_]*" data-measured="0"' <<<"$dom" | cut -d'"' -f2 | tr '\n' ' ')
[ "$unmeasured" = "formation_rms " ] || fail "not measured: '$unmeasured', expected only formation_rms"
echo "report_chromium: headline with $rows figures above the charts"

# Every chart, with data elements, in the DOM as the browser parsed it.
tr '\n' ' ' <"$out/dom.html" | sed 's/<svg /\n<svg /g; s/<\/svg>/<\/svg>\n/g' >"$work/svgs.txt"
for id in topdown errors error-by-range box-width latency; do
  line=$(grep -m1 "^<svg id=\"$id\"" "$work/svgs.txt" || true)
  [ -n "$line" ] || fail "no <svg id=\"$id\"> in the DOM"
  n=$(grep -oE '<(polyline|circle|rect) class="data"' <<<"$line" | wc -l)
  [ "$n" -gt 0 ] || fail "<svg id=\"$id\"> has no data elements"
  echo "report_chromium: svg#$id: $n data elements"
done
# Camera frames: each <img> decoded in the browser (its onload marks it).
frames=$(grep -o '<img class="frame"' "$out/dom.html" | wc -l)
decoded=$(grep -o 'data-decoded="1"' "$out/dom.html" | wc -l)
[ "$frames" -ge 1 ] || fail "no camera frames in the report"
[ "$decoded" = "$frames" ] || fail "$decoded of $frames camera frames decoded"
thumbs=$(grep -o '<img class="frame" width="320" height="180"' "$out/dom.html" | wc -l)
[ "$thumbs" = "$frames" ] || fail "$thumbs of $frames camera frames are 320x180 thumbnails (the log's are 480x270)"
echo "report_chromium: $frames frames decoded; screenshot $out/report.png ($colours colours)"

#!/usr/bin/env bash
# Issue 17, item 2: report.html in a real browser. scanhead_run writes a results folder (every plot), headless
# Chromium loads its report.html from the file system (no server, no network), and the page's own load check
# (report/html_page: data-* on <body>) must say that every image decoded and the tables are there; then the
# screenshot must show them (many colours, not a blank page). The same for scanhead_compare's comparison.html and a
# study's summary.html.
# usage: report_browser.sh SCANHEAD_RUN SCANHEAD_STUDY     exit 77: no chromium here (install_deps.sh installs it)
set -euo pipefail
RUN=$1
STUDY=$2
BROWSER=$(command -v chromium || command -v chromium-browser || true)
[ -n "$BROWSER" ] || { echo "SKIP: no chromium (scripts/install_deps.sh installs it)"; exit 77; }
TMP=$(mktemp -d /tmp/scanhead_report.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# browse PAGE MIN_IMAGES MIN_TABLES: loads PAGE, checks its load check and its screenshot.
browse() {
  local page=$1 min_images=$2 min_tables=$3 name
  name=$(basename "$(dirname "$page")")_$(basename "$page" .html)
  # --virtual-time-budget: the page's load event and script run before the DOM is dumped.
  timeout 120 "$BROWSER" --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir="$TMP/profile" \
    --virtual-time-budget=10000 --dump-dom "file://$page" > "$TMP/$name.dom" 2> "$TMP/$name.err" \
    || fail "chromium could not load $page: $(tail -3 "$TMP/$name.err")"
  local body images loaded tables
  body=$(grep -o '<body[^>]*>' "$TMP/$name.dom" | head -1)
  images=$(sed -n 's/.*data-images="\([0-9]*\)".*/\1/p' <<<"$body")
  loaded=$(sed -n 's/.*data-images-loaded="\([0-9]*\)".*/\1/p' <<<"$body")
  tables=$(sed -n 's/.*data-tables="\([0-9]*\)".*/\1/p' <<<"$body")
  [ -n "$images" ] || fail "$page: the load check did not run (body: $body)"
  [ "$images" -ge "$min_images" ] || fail "$page: $images images, expected at least $min_images"
  [ "$loaded" -eq "$images" ] || fail "$page: only $loaded of $images images decoded"
  [ "$tables" -ge "$min_tables" ] || fail "$page: $tables tables, expected at least $min_tables"
  timeout 120 "$BROWSER" --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir="$TMP/profile" \
    --hide-scrollbars --virtual-time-budget=10000 --window-size=1280,2400 --screenshot="$TMP/$name.png" \
    "file://$page" > /dev/null 2>&1 || fail "no screenshot of $page"
  /usr/bin/python3 - "$TMP/$name.png" << 'PY' || fail "$page: the screenshot does not show the report"
import sys
import numpy as np
from PIL import Image
pixels = np.asarray(Image.open(sys.argv[1]).convert("RGB")).reshape(-1, 3)
colours = len(np.unique(pixels[::7], axis=0))
ink = float(np.mean(np.any(pixels < 200, axis=1)))
print("screenshot %s: %d colours, %.0f %% ink" % (sys.argv[1], colours, 100 * ink))
sys.exit(0 if colours > 200 and ink > 0.02 else 1)  # a blank page: one colour, no ink
PY
  echo "$page: $loaded/$images images decoded, $tables tables"
}

# A THESIS job of two squares: every plot, the crops, the corner table.
"$RUN" --job squares:rows=1,columns=2 --out "$TMP/squares" --quiet > /dev/null
[ -s "$TMP/squares/report.html" ] || fail "no report.html in the results folder"
browse "$TMP/squares/report.html" 8 4

# Two runs compared: the table and the chart.
"$RUN" --job squares:rows=1,columns=2 --set nc.fir_t1_s=4e-4 --out "$TMP/squares_t1" --plots none --quiet > /dev/null
"$(dirname "$RUN")/scanhead_compare" "$TMP/squares" "$TMP/squares_t1" --out "$TMP/compare" > "$TMP/compare.out" 2>&1 \
  || fail "scanhead_compare: $(cat "$TMP/compare.out")"
browse "$TMP/compare/comparison.html" 1 1

# A study's summary page: its tables (worst cases, cases), its plot.
cat > "$TMP/study.yaml" << 'YAML'
jobs: [corner]
grid: {nc.fir_t1_s: [2.0e-4, 3.0e-4]}
YAML
"$STUDY" run "$TMP/study.yaml" --out "$TMP/study" > "$TMP/study.out" 2>&1 || fail "study: $(cat "$TMP/study.out")"
[ -s "$TMP/study/summary.html" ] || fail "no summary.html in the study folder"
browse "$TMP/study/summary.html" 1 2  # one job: the grid plot (no layers to plot across)
echo "report pages: OK"

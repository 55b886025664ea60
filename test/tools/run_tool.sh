#!/usr/bin/env bash
# scanhead_run's results and plots: --plots none|summary|all (which PNG plots, whether python starts
# at all), the phase breakdown on the run line (also with --quiet), a failing plot script (an error:
# non-zero exit, no folder published, the message names --plots none), and plot_results.py run by
# hand on a folder.
set -uo pipefail
run=${1:-scanhead_run}
script=${2:-$(cd "$(dirname "$0")/../.." && pwd)/scripts/plot_results.py}
tmp=$(mktemp -d /tmp/scanhead_run_tool.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
ok() { echo "ok   $*"; }
plots="energy_map_plot.png quality.png speed.png contour_error.png corner_zoom.png"
data="metrics.yaml trace.csv job.yaml job.png energy_map.png energy_map_16bit.png energy_map.tiff energy_map.yaml"

# Every python3 started with this PYTHONPATH imports sitecustomize first: it leaves a marker file
# (or, with SCANHEAD_TEST_PLOT_FAIL set, fails), so the test sees whether python ran at all.
mkdir -p "$tmp/site"
cat > "$tmp/site/sitecustomize.py" <<PY
import os
open("$tmp/python_started", "a").close()
if os.environ.get("SCANHEAD_TEST_PLOT_FAIL"):
    raise SystemExit("test: plotting fails on purpose")
PY
export PYTHONPATH="$tmp/site"

check_run() {  # check_run LABEL PLOTS EXPECTED_PLOTS ABSENT_PLOTS PYTHON(yes|no) [ARGS...]
  local label=$1 set=$2 present=$3 absent=$4 python=$5
  shift 5
  rm -f "$tmp/python_started"
  local out code
  out=$("$run" --job corner --out "$tmp/$label" --quiet --plots "$set" "$@" 2>&1); code=$?
  [ $code -eq 0 ] || { fail "$label: exit code $code: $out"; return; }
  for f in $data $present; do [ -s "$tmp/$label/$f" ] || { fail "$label: no $f"; return; }; done
  for f in $absent; do [ ! -e "$tmp/$label/$f" ] || { fail "$label: $f written"; return; }; done
  if [ "$python" = yes ] && [ ! -e "$tmp/python_started" ]; then fail "$label: python did not start"; return; fi
  if [ "$python" = no ] && [ -e "$tmp/python_started" ]; then fail "$label: python started"; return; fi
  # One line with the phases, also under --quiet.
  local line
  line=$(grep -E '^run: [0-9.]+ s wall \(chain [0-9.]+ s, results [0-9.]+ s, plots [0-9.]+ s\)' <<<"$out")
  [ "$(wc -l <<<"$line")" -eq 1 ] && [ -n "$line" ] || { fail "$label: no phase breakdown in: $out"; return; }
  if [ "$set" = none ] && ! grep -q "plots 0.00 s" <<<"$line"; then fail "$label: plots timed without plots: $line"; return; fi
  ok "$label: $line"
}

check_run all all "$plots" "" yes
check_run summary summary "energy_map_plot.png quality.png" "speed.png contour_error.png corner_zoom.png" yes
check_run none none "" "$plots" no

# A failing plot script: plots asked for and not made are an error; nothing is published, and the
# message says how to run without python.
rm -f "$tmp/python_started"
out=$(SCANHEAD_TEST_PLOT_FAIL=1 "$run" --job corner --out "$tmp/failing" --quiet 2>&1); code=$?
if [ $code -eq 0 ] || ! grep -q "error: plots failed: .*plot_results.py exited with status 1" <<<"$out" ||
  ! grep -q -- "--plots none" <<<"$out" || [ -e "$tmp/failing" ] || ls -A "$tmp" | grep -q '^\.failing\.'; then
  fail "failing plots: exit $code: $out"
else
  ok "failing plots: exit $code, $(grep "scanhead_run: error:" <<<"$out")"
fi

# A bad --plots value names the option and the words.
out=$("$run" --job corner --out "$tmp/bad" --quiet --plots some 2>&1); code=$?
if [ $code -eq 0 ] || ! grep -q "none, summary or all" <<<"$out" || [ -e "$tmp/bad" ]; then
  fail "bad --plots: exit $code: $out"
else
  ok "bad --plots: $out"
fi

# plot_results.py by hand on the folder written without plots; --plots summary.
unset PYTHONPATH
if /usr/bin/python3 -c "import matplotlib" 2> /dev/null; then
  if ! /usr/bin/python3 "$script" "$tmp/none" > "$tmp/by_hand.log" 2>&1; then
    fail "plot_results.py by hand: $(cat "$tmp/by_hand.log")"
  else
    missing=""
    for f in $plots; do [ -s "$tmp/none/$f" ] || missing="$missing $f"; done
    [ -z "$missing" ] && ok "plot_results.py by hand: $plots" || fail "plot_results.py by hand: no$missing"
  fi
  cp -r "$tmp/none" "$tmp/by_hand_summary" && rm -f "$tmp/by_hand_summary/"*_plot.png "$tmp/by_hand_summary/quality.png" \
    "$tmp/by_hand_summary/speed.png"
  /usr/bin/python3 "$script" --plots summary "$tmp/by_hand_summary" > /dev/null 2>&1 &&
    [ -s "$tmp/by_hand_summary/quality.png" ] && [ ! -e "$tmp/by_hand_summary/speed.png" ] &&
    ok "plot_results.py --plots summary by hand" || fail "plot_results.py --plots summary by hand"
else
  echo "skip plot_results.py by hand: no python3-matplotlib"
fi
# Progress in a log (stderr not a terminal): one line every 10 % with the time left, no carriage returns;
# --quiet: none.
"$run" --job hatch:size=0.02 --out "$tmp/progress" --plots none 2> "$tmp/progress.err" > /dev/null
lines=$(grep -c "% of 402784 samples .* s left$" "$tmp/progress.err")
if [ "$lines" -ge 9 ] && [ "$lines" -le 11 ] && ! grep -q $'\r' "$tmp/progress.err"; then
  ok "progress in a log: $lines lines, one per 10 %"
else
  fail "progress in a log: $lines lines: $(head -c 400 "$tmp/progress.err" | tr '\r' '|')"
fi
"$run" --job hatch:size=0.02 --out "$tmp/progress" --plots none --quiet 2> "$tmp/quiet.err" > /dev/null
grep -q "% of" "$tmp/quiet.err" && fail "--quiet printed progress" || ok "--quiet: no progress"
echo "$failures failure(s)"
[ $failures -eq 0 ]

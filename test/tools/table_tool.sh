#!/usr/bin/env bash
# scanhead_table: the error report of the THESIS 65 × 65 table (bilinear ~4.19 µm max) and of the
# bicubic option (< 1 µm), on the nominal and the OPT table 2 machine; save/load gives the same
# report; bad arguments and files fail with a message.
set -euo pipefail
tool=${1:-scanhead_table}
tmp=$(mktemp -d /tmp/scanhead_table.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
value() { sed -n "s/^$1: //p" <<<"$2"; }
check() {  # name report expression-on-max
  local max
  max=$(value max_error_m "$2")
  /usr/bin/python3 -c "import sys; m = float('$max'); sys.exit(0 if ($3) else 1)" \
    || { echo "FAIL $1: max_error_m $max does not satisfy $3"; echo "$2"; exit 1; }
}
for defects in "" "--defects opt_table2"; do
  out=$("$tool" --probes 129 $defects)
  for key in nodes interpolation defects max_error_m rms_error_m worst_point_m; do
    grep -q "^$key:" <<<"$out" || { echo "FAIL: no $key"; echo "$out"; exit 1; }
  done
  check "bilinear $defects" "$out" "3.5e-6 < m < 5e-6"
  out=$("$tool" --probes 129 --interpolation bicubic $defects)
  check "bicubic $defects" "$out" "m < 1e-6"
done
"$tool" --probes 65 --save "$tmp/t.txt" > "$tmp/a.yaml"
"$tool" --probes 65 --load "$tmp/t.txt" > "$tmp/b.yaml"
[ "$(value max_error_m "$(cat "$tmp/a.yaml")")" = "$(value max_error_m "$(cat "$tmp/b.yaml")")" ] \
  || { echo "FAIL: loaded table reports differently"; cat "$tmp/a.yaml" "$tmp/b.yaml"; exit 1; }
if "$tool" --interpolation cubic 2>"$tmp/err"; then echo "FAIL: bad interpolation accepted"; exit 1; fi
grep -q "bilinear" "$tmp/err" || { echo "FAIL: message"; cat "$tmp/err"; exit 1; }
printf '# scanhead correction table v1\nnodes 3\n' > "$tmp/bad.txt"
if "$tool" --load "$tmp/bad.txt" 2>"$tmp/err"; then echo "FAIL: bad table accepted"; exit 1; fi
grep -q "bad.txt" "$tmp/err" || { echo "FAIL: message does not name the file"; cat "$tmp/err"; exit 1; }
# Bounds: --probes (work ~ P²) and a table declaring more nodes than its file can hold.
if "$tool" --probes 1000000 2>"$tmp/err"; then echo "FAIL: --probes 1000000 accepted"; exit 1; fi
grep -qF -- "--probes: must be an integer in [2, 2049] (got '1000000')" "$tmp/err" || { echo "FAIL: message"; cat "$tmp/err"; exit 1; }
printf '# scanhead correction table v1\nnodes 2049\nhalf_width_m 0.1\n' > "$tmp/huge.txt"
if "$tool" --load "$tmp/huge.txt" 2>"$tmp/err"; then echo "FAIL: 2049-node table accepted"; exit 1; fi
grep -qF "huge.txt:2: nodes 2049 needs 2049² node lines" "$tmp/err" || { echo "FAIL: message"; cat "$tmp/err"; exit 1; }
echo "scanhead_table: reports, save/load and errors ok"

#!/usr/bin/env bash
# scanhead_galvo: the three commands print the documented keys; identification within 5 %;
# the KM0 report is written with a verdict; bad arguments fail with a message.
set -euo pipefail
tool=${1:-scanhead_galvo}
tmp=$(mktemp -d /tmp/scanhead_galvo.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
for axis in x y; do
  out=$("$tool" loops --axis $axis)
  for key in bandwidth_hz position_crossover_rad_s position_phase_margin_deg speed_crossover_rad_s current_crossover_rad_s; do
    grep -q "^$key:" <<<"$out" || { echo "FAIL loops --axis $axis: no $key"; echo "$out"; exit 1; }
  done
done
out=$("$tool" identify --axis y)
for key in R_ohm L_h Kc_nm_per_a B_nms Jeq_kgm2; do
  grep -q "$key" <<<"$out" || { echo "FAIL identify: no $key"; echo "$out"; exit 1; }
done
"$tool" km0 --axis y --out "$tmp/km0" > "$tmp/km0.yaml"
[ -f "$tmp/km0/km0_report.yaml" ] || { echo "FAIL km0: no km0_report.yaml"; exit 1; }
grep -q "verdict" "$tmp/km0.yaml" || { echo "FAIL km0: no verdict"; exit 1; }
if "$tool" loops --axis z 2>"$tmp/err"; then echo "FAIL: --axis z accepted"; exit 1; fi
grep -q -- "--axis: must be x or y (got 'z')" "$tmp/err" || { echo "FAIL: message"; cat "$tmp/err"; exit 1; }
if "$tool" km0 --axis x 2>"$tmp/err"; then echo "FAIL: km0 without --out accepted"; exit 1; fi
echo "scanhead_galvo: loops, identify and km0 ok"

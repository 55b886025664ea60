#!/usr/bin/env bash
# scripts/fit_servo_friction.py --evaluate-only on a 1 × 2 block: the table has the three recipes with
# both controllers, and its recipe-1 shares under 10 µm are those of scanhead_run's own metrics.yaml
# for the same job and controller (read here with a YAML parser, not the script's regular
# expressions); a missing scanhead_run is named.
set -euo pipefail
run=${1:?usage: fit_friction_tool.sh SCANHEAD_RUN}
here=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d /tmp/scanhead_fit.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
out=$(/usr/bin/python3 "$here/scripts/fit_servo_friction.py" --scanhead-run "$run" --evaluate-only --rows 1 --columns 2)
for c in pd hinf; do
  for r in 1 2 3; do
    grep -Eq "^$c +$r +\| +[0-9.]+ / +[0-9.]+ " <<<"$out" || { echo "FAIL: no row for $c, recipe $r"; echo "$out"; exit 1; }
  done
  ours=$(awk -v c=$c '$1 == c && $2 == "1" {print $4}' <<<"$out")
  "$run" --config "$here/config/scanhead.yaml" --job "squares:recipe=1,rows=1,columns=2" --set recipe.preset=thesis1 \
    --set energy.pixel_m=3.5e-5 \
    --set servo.position_controller=$c --plots none --quiet --out "$tmp/r1_$c" > /dev/null
  direct=$(/usr/bin/python3 -c "
import yaml, sys
m = yaml.safe_load(open('$tmp/r1_$c/metrics.yaml'))
print('%.2f' % (100 * m['contour_error']['same_instant']['contour']['share_under_10um']))")
  [ "$ours" = "$direct" ] || { echo "FAIL: $c: the script reads $ours %, metrics.yaml has $direct %"; exit 1; }
  echo "$c: recipe 1 under 10 um: $ours % in the table and in metrics.yaml"
done
grep -q "H∞ better than pd in [0-9]* of the [0-9]* cells" <<<"$out" || { echo "FAIL: no H∞ count"; echo "$out"; exit 1; }
if /usr/bin/python3 "$here/scripts/fit_servo_friction.py" --scanhead-run "$tmp/none" --evaluate-only \
  --rows 1 --columns 1 2> "$tmp/err" > /dev/null; then
  echo "FAIL: a missing scanhead_run was accepted"; exit 1
fi
grep -q "is not an executable file" "$tmp/err" || { echo "FAIL: message"; cat "$tmp/err"; exit 1; }
echo "fit_servo_friction.py: table ok"

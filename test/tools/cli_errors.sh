#!/usr/bin/env bash
# scanhead_run on bad input: non-zero exit, a message naming the file and field, no results folder.
set -uo pipefail
run=${1:-scanhead_run}
tmp=$(mktemp -d /tmp/scanhead_cli.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
failures=0

job() {  # job NAME BODY: writes a one-polyline job file
  printf 'name: t\npolylines:\n  - %s\n' "$2" > "$tmp/$1.yaml"
}
expect_error() {  # expect_error LABEL EXPECTED_TEXT ARGS...
  local label=$1 expected=$2
  shift 2
  local out
  out=$("$run" --out "$tmp/out_$label" --quiet "$@" 2>&1)
  local code=$?
  if [ $code -eq 0 ]; then
    echo "FAIL $label: exit code 0"; failures=$((failures + 1))
  elif ! grep -qF -- "$expected" <<<"$out"; then
    echo "FAIL $label: message lacks '$expected': $out"; failures=$((failures + 1))
  elif [ -e "$tmp/out_$label" ] || ls -a "$tmp" | grep -q partial; then
    echo "FAIL $label: a results folder was left behind"; failures=$((failures + 1))
  else
    echo "ok   $label: $out"
  fi
}

printf 'name: t\npolylines:\n  - {type: mark, speed: [1\n' > "$tmp/malformed.yaml"
expect_error malformed "malformed.yaml:" --job "$tmp/malformed.yaml"
job unknown_key '{type: mark, speed: 1, power: 1, colour: red, points: [[0, 0], [0.001, 0]]}'
expect_error unknown_key "unknown_key.yaml:3: polylines[0]: unknown key 'colour'" --job "$tmp/unknown_key.yaml"
job nan '{type: mark, speed: .nan, power: 1, points: [[0, 0], [0.001, 0]]}'
expect_error nan "nan.yaml:3: polylines[0].speed: '.nan' is not a number" --job "$tmp/nan.yaml"
job zero_speed '{type: mark, speed: 0, power: 1, points: [[0, 0], [0.001, 0]]}'
expect_error zero_speed "zero_speed.yaml: polylines[0].speed must be > 0 m/s (got 0)" --job "$tmp/zero_speed.yaml"
job negative_power '{type: mark, speed: 1, power: -3, points: [[0, 0], [0.001, 0]]}'
expect_error negative_power "polylines[0].power must be >= 0 W (got -3)" --job "$tmp/negative_power.yaml"
job outside '{type: mark, speed: 1, power: 1, points: [[0, 0], [0.5, 0]]}'
expect_error outside "polylines[0].points[1] = (0.5, 0) m lies outside the field" --job "$tmp/outside.yaml"
job one_point '{type: mark, speed: 1, power: 1, points: [[0, 0]]}'
expect_error one_point "polylines[0].points: needs at least 2 points (got 1)" --job "$tmp/one_point.yaml"
expect_error missing_file "no_such.yaml: cannot open the job file" --job "$tmp/no_such.yaml"
expect_error unknown_builtin "no such job file, and no built-in job named 'pentagons'" --job pentagons
expect_error unknown_setting "unknown key 'nc.fir_t3_s'" --set nc.fir_t3_s=1
expect_error bad_setting "nc.period_s (--set): 'fast' is not a number" --set nc.period_s=fast
expect_error bad_range "nc.fir_t1_s must be >= 0" --set nc.fir_t1_s=-1e-5
expect_error bad_argument "unknown argument '--jbo'" --jbo corner
# Issue 7's settings: named before the run starts, never after it.
expect_error bad_crop "energy.crop_regions: '0,0,1' is not x0,y0,x1,y1[,name]" --set energy.crop_regions=0,0,1
expect_error bad_defocus "energy.defocus_mode must be none, fixed or field (got 'sphere')" --set energy.defocus_mode=sphere
expect_error crop_off_map "region far lies outside the energy map" --set "energy.crop_regions=0.1,0.1,0.11,0.11,far"
expect_error bad_window "energy.same_instant_window_s must be in [0, 0.01] s" --set energy.same_instant_window_s=-1
expect_error bad_thermal "thermal.cell_m must be > 0" --set thermal.enabled=true --set thermal.cell_m=0
expect_error bad_spill "cannot create the tile spill file" --job squares:rows=1,columns=1 --set energy.tile_cache_bytes=1048576 \
  --set energy.spill_dir=/nonexistent/dir

# Bounded YAML: duplicate keys (job, config, a setting given twice), aliases expanding too far.
job dup_key '{type: mark, speed: 1, power: 1, speed: 2, points: [[0, 0], [0.001, 0]]}'
expect_error dup_key "dup_key.yaml:3:38: duplicate key 'polylines[0].speed' (first at line 3)" --job "$tmp/dup_key.yaml"
printf 'nc:\n  period_s: 1.0e-5\n  period_s: 2.0e-5\n' > "$tmp/dup_config.yaml"
expect_error dup_config "dup_config.yaml:3:3: duplicate key 'nc.period_s' (first at line 2)" --config "$tmp/dup_config.yaml"
printf 'nc: {period_s: 1.0e-5}\nnc.period_s: 2.0e-5\n' > "$tmp/twice.yaml"
expect_error twice_config "twice.yaml:2: nc.period_s is given twice (first at" --config "$tmp/twice.yaml"
{ echo 'name: bomb'; echo 'a0: &a0 [[0, 0], [0.001, 0]]'
  for k in 1 2 3 4 5 6 7 8; do printf 'a%d: &a%d [*a%d, *a%d, *a%d, *a%d, *a%d, *a%d, *a%d, *a%d]\n' $k $k $((k-1)) $((k-1)) $((k-1)) $((k-1)) $((k-1)) $((k-1)) $((k-1)) $((k-1)); done
  echo 'polylines: [{type: mark, speed: 1, power: 1, points: *a8}]'; } > "$tmp/bomb.yaml"
expect_error alias_bomb "YAML aliases expand to more than" --job "$tmp/bomb.yaml"

# A foreign folder is never overwritten.
mkdir -p "$tmp/foreign" && echo data > "$tmp/foreign/keep.txt"
out=$("$run" --out "$tmp/foreign" --quiet 2>&1); code=$?
if [ $code -eq 0 ] || [ ! -f "$tmp/foreign/keep.txt" ] || [ -e "$tmp/foreign/metrics.yaml" ]; then
  echo "FAIL foreign folder: $out"; failures=$((failures + 1))
else
  echo "ok   foreign folder: $out"
fi
# Issue 14: impossible settings and jobs are errors naming the key or field and the range; a job
# beyond the limits is refused by the run plan, naming the key to raise. (--plots none where the
# refusal comes from BatchChain::run: no plotter is started that the error would have to cancel.)
expect_error period_range "nc.period_s must be in [1e-06, 0.001] s" --set nc.period_s=1
expect_error controller_range "servo.controller_rate_hz must be in [1000, 1e+06] Hz" --set servo.controller_rate_hz=1e12
expect_error fir_periods "nc.fir_t1_s must be <= 10000" --set nc.fir_t1_s=1e3
expect_error pixel_spot "energy.pixel_m must be <= energy.spot_diameter_m/2" --set energy.pixel_m=1
expect_error truncation "energy.truncation_radii must be <= 5" --set energy.truncation_radii=6
job fast '{type: mark, speed: 1e300, power: 200, points: [[0, 0], [0.001, 0]]}'
expect_error fast "fast.yaml: polylines[0].speed = 1e+300 m/s is above what the galvos can reach" --job "$tmp/fast.yaml" --plots none
job power '{type: mark, speed: 1, power: 1e15, points: [[0, 0], [0.001, 0]]}'
expect_error power "power.yaml: polylines[0].power = 1e+15 W is above any continuous-wave laser" --job "$tmp/power.yaml" --plots none
expect_error tail "above limits.max_machine_time_s" --set nc.tail_s=1e6 --plots none
echo "$failures failure(s)"
[ $failures -eq 0 ]

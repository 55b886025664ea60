#!/usr/bin/env bash
# Absurd settings and jobs (issue 14): each gives a clear error (non-zero exit, the key or field and
# the range in the message, no results folder left) or, when possible but questionable, a correct
# result with the warning in metrics.yaml; every case within 5 s of wall and 1 GiB of peak memory.
#   test/reliability/absurd_settings.sh [scanhead_run]
set -uo pipefail
run=${1:-scanhead_run}
tmp=$(mktemp -d /tmp/scanhead_absurd.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
failures=0
max_wall_s=5
max_rss_kb=1048576  # 1 GiB

fail() {
  echo "FAIL $1"
  failures=$((failures + 1))
}
job() {  # job NAME POLYLINE: a one-polyline job file
  printf 'name: %s\npolylines:\n  - %s\n' "$1" "$2" > "$tmp/$1.yaml"
}
# timed LABEL ARGS...: runs scanhead_run under /usr/bin/time; sets out, code, wall, rss
timed() {
  local label=$1
  shift
  out=$(/usr/bin/time -f 'TIME %e %M' -o "$tmp/time_$label" "$run" --out "$tmp/out_$label" --quiet --plots none "$@" 2>&1)
  code=$?
  read -r _ wall rss < <(grep '^TIME' "$tmp/time_$label")
  if awk -v w="$wall" -v m="$max_wall_s" 'BEGIN { exit !(w > m) }'; then
    fail "$label: took $wall s (> $max_wall_s s)"
    return 1
  fi
  if [ "$rss" -gt "$max_rss_kb" ]; then
    fail "$label: peak memory $rss kB (> 1 GiB)"
    return 1
  fi
  return 0
}
expect_error() {  # expect_error LABEL EXPECTED_TEXT ARGS...
  local label=$1 expected=$2
  shift 2
  timed "$label" "$@" || return
  if [ $code -eq 0 ]; then
    fail "$label: exit code 0"
  elif grep -q "std::bad_alloc\|terminate called" <<<"$out"; then
    fail "$label: a bare exception: $out"
  elif ! grep -qF -- "$expected" <<<"$out"; then
    fail "$label: message lacks '$expected': $out"
  elif [ -e "$tmp/out_$label" ] || ls -a "$tmp" | grep -qE "partial|staging|out_$label\.lock"; then
    fail "$label: a results folder, staging folder or lock was left behind: $(ls -a "$tmp" | tr '\n' ' ')"
  else
    echo "ok   $label ($wall s, $((rss / 1024)) MiB): $out"
  fi
}
expect_warning() {  # expect_warning LABEL EXPECTED_TEXT ARGS...: runs, warns on stderr and in metrics.yaml
  local label=$1 expected=$2
  shift 2
  timed "$label" "$@" || return
  local metrics="$tmp/out_$label/metrics.yaml"
  if [ $code -ne 0 ]; then
    fail "$label: exit code $code: $out"
  elif [ "$(grep -cF -- "warning: " <<<"$out")" -ne 1 ] || ! grep -qF -- "$expected" <<<"$out"; then
    fail "$label: stderr lacks one warning '$expected': $out"
  elif ! grep -q '^warnings:' "$metrics" || ! grep -qF -- "$expected" "$metrics"; then
    fail "$label: metrics.yaml lacks the warning '$expected'"
  elif ! awk '/^samples:/ { s = $2 } /^deposited_energy_j:/ { e = $2 } END { exit !(s > 0 && e > 0) }' "$metrics"; then
    fail "$label: no result (samples or energy missing)"
  else
    echo "ok   $label ($wall s, $((rss / 1024)) MiB): warned and ran"
  fi
}

# The cases of issue 14 ("Work and memory unbounded", "Nonsense accepted silently").
job slow '{type: mark, speed: 1.0e-12, power: 200, points: [[0, 0], [0.001, 0]]}'
expect_error speed_1e-12 "above limits.max_machine_time_s" --job "$tmp/slow.yaml"
job dwell '{type: mark, power: 200, dwell: 1.0e9, points: [[0, 0]]}'
expect_error dwell_1e9 "above limits.max_machine_time_s" --job "$tmp/dwell.yaml"
expect_error tail_1e6 "tail nc.tail_s 278 h), above limits.max_machine_time_s" --set nc.tail_s=1e6
expect_error controller_1e12 "servo.controller_rate_hz must be in [1000, 1e+06] Hz" --set servo.controller_rate_hz=1e12
expect_error fir_1e3 "nc.fir_t1_s must be <= 10000·nc.period_s" --set nc.fir_t1_s=1e3
expect_error period_1e-12 "nc.period_s must be in [1e-06, 0.001] s" --set nc.period_s=1e-12
expect_error period_1 "nc.period_s must be in [1e-06, 0.001] s" --set nc.period_s=1
job fast '{type: mark, speed: 1.0e300, power: 200, points: [[0, 0], [0.001, 0]]}'
expect_error speed_1e300 "fast.yaml: polylines[0].speed = 1e+300 m/s is above what the galvos can reach" \
  --job "$tmp/fast.yaml"
job power '{type: mark, speed: 1, power: 1.0e15, points: [[0, 0], [0.001, 0]]}'
expect_error power_1e15 "power.yaml: polylines[0].power = 1e+15 W is above any continuous-wave laser" \
  --job "$tmp/power.yaml"
expect_error pixel_1 "energy.pixel_m must be <= energy.spot_diameter_m/2" --set energy.pixel_m=1
expect_error truncation_100 "energy.truncation_radii must be <= 5" --set energy.truncation_radii=100
# More settings that sized work or memory without a bound.
expect_error pixel_1e-9 "energy.pixel_m must be >= energy.spot_diameter_m/100" --set energy.pixel_m=1e-9
expect_error substep_1e-9 "energy.max_substep_radii must be >= 0.01" --set energy.method=sampled \
  --set energy.max_substep_radii=1e-9
expect_error chunk_1e12 "stream.chunk_samples must be <= 1000000" --set stream.chunk_samples=1e12
expect_error spot_1e-12 "energy.spot_diameter_m must be >= 2·M²·λ/π" --set energy.spot_diameter_m=1e-12 \
  --set energy.pixel_m=1e-14
expect_error recipe_power "recipe.hatch_power_w must be <= 1e+06 W" --set recipe.hatch_power_w=1e15
expect_error recipe_speed "recipe.hatch_speed_mps = 1e+300 m/s is above what the galvos can reach" \
  --set recipe.preset=custom --set recipe.hatch_speed_mps=1e300
expect_error mark_delay "above limits.max_machine_time_s" --set nc.mark_delay_s=1e9
expect_error laser_delay "sets it: recipe.laser_off_delay_s), above limits.max_machine_time_s" --set recipe.laser_off_delay_s=1e9
expect_error memory_limit "(limits.max_memory_bytes)" --set limits.max_memory_bytes=1e6
expect_error samples_limit "exceed limits.max_samples" --set limits.max_samples=100
expect_error table_nodes "nc.igt.table_nodes must be in 2...1025" --set nc.igt.mode=table --set nc.igt.table_nodes=4097

# Questionable but possible: a correct result, the warning once on stderr and in metrics.yaml.
job kilowatt '{type: mark, speed: 1, power: 1500, points: [[0, 0], [0.002, 0]]}'
expect_warning power_1500 "polylines[0].power = 1500 W is above the ~1 kW of LPBF lasers" --job "$tmp/kilowatt.yaml"
job quick '{type: mark, speed: 12, power: 200, points: [[0, 0], [0.004, 0]]}'
expect_warning speed_12 "polylines[0].speed = 12 m/s is above LPBF mark speeds" --job "$tmp/quick.yaml"
expect_warning coarse_pixel "energy.pixel_m = 2e-05 m is coarser than energy.spot_diameter_m/5" \
  --set energy.pixel_m=2e-5
# And the default job stays warning-free.
timed defaults || true
if [ "${code:-1}" -ne 0 ] || grep -q "warning" <<<"$out" || grep -q '^warnings:' "$tmp/out_defaults/metrics.yaml"; then
  fail "defaults: not a clean run: $out"
else
  echo "ok   defaults ($wall s): no warning"
fi

echo "$failures failure(s)"
[ $failures -eq 0 ]

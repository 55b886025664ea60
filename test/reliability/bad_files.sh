#!/usr/bin/env bash
# Bad input files and tool options (issue 14): each must fail with a clear message, a non-zero exit,
# no results folder left, in < 5 s of wall time and < 1 GiB of peak memory (/usr/bin/time).
# Cases: a YAML alias bomb, an 89 MB YAML job (generated here), duplicate keys in a job, a config
# and a defect set, a correction table declaring 2049 nodes, a table with half_width_m 1e300,
# $$LAYERS/1000000000 in a CLI file, a self-intersecting polygon, unbounded tool options.
#
# Usage: test/reliability/bad_files.sh <build>/devel/lib/scanhead
set -uo pipefail
bin=${1:?usage: bad_files.sh <dir with scanhead_run, scanhead_table, scanhead_optics>}
tmp=$(mktemp -d /tmp/scanhead_bad_files.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
failures=0
max_s=5
max_kib=$((1024 * 1024))

if [ ! -x /usr/bin/time ]; then
  echo "bad_files: /usr/bin/time not found (apt-get install time)" >&2
  exit 1
fi

# expect_error LABEL EXPECTED_TEXT PROGRAM ARGS...: PROGRAM must fail naming EXPECTED_TEXT, leave
# no $tmp/out_LABEL (nor any staging folder), within the time and memory bounds.
expect_error() {
  local label=$1 expected=$2 program=$3
  shift 3
  local out code wall kib
  out=$(/usr/bin/time -o "$tmp/time_$label" -f '%e %M' "$bin/$program" "$@" 2>&1)
  code=$?
  read -r wall kib < <(tail -n 1 "$tmp/time_$label")
  if [ $code -eq 0 ]; then
    echo "FAIL $label: exit code 0: $out"; failures=$((failures + 1))
  elif ! grep -qF -- "$expected" <<<"$out"; then
    echo "FAIL $label: message lacks '$expected': $out"; failures=$((failures + 1))
  elif [ -e "$tmp/out_$label" ] || ls -a "$tmp" | grep -q partial; then
    echo "FAIL $label: a results folder was left behind"; failures=$((failures + 1))
  elif ! awk -v w="$wall" -v m="$max_s" 'BEGIN { exit !(w < m) }'; then
    echo "FAIL $label: took $wall s (limit $max_s s)"; failures=$((failures + 1))
  elif [ "$kib" -ge $max_kib ]; then
    echo "FAIL $label: peak memory $kib KiB (limit $max_kib KiB)"; failures=$((failures + 1))
  else
    echo "ok   $label (${wall} s, $((kib / 1024)) MiB): $(head -c 300 <<<"$out" | head -n 2)"
  fi
}
run() {  # run LABEL EXPECTED ARGS...: scanhead_run with its own --out
  local label=$1 expected=$2
  shift 2
  expect_error "$label" "$expected" scanhead_run --out "$tmp/out_$label" --quiet "$@"
}

# 1. Alias bomb: 9 levels of 9 aliases, ~400 bytes expanding to 9^9 ≈ 3.9e8 points.
{
  echo "name: bomb"
  echo "p0: &p0 [[0, 0], [0.001, 0]]"
  for k in 1 2 3 4 5 6 7 8 9; do
    j=$((k - 1))
    printf 'p%d: &p%d [*p%d, *p%d, *p%d, *p%d, *p%d, *p%d, *p%d, *p%d, *p%d]\n' $k $k $j $j $j $j $j $j $j $j $j
  done
  echo "polylines: [{type: mark, speed: 1, power: 100, points: *p9}]"
} > "$tmp/bomb.yaml"
run alias_bomb "YAML aliases expand to more than" --job "$tmp/bomb.yaml"

# 2. An 89 MB YAML job (~1.1 M polylines): refused from its size before it is read.
awk 'BEGIN { print "name: big"; print "polylines:";
  line = "  - {type: mark, speed: 1, power: 100, points: [[0.001, 0.002], [0.003, 0.004]]}";
  for (i = 0; i < 89e6 / (length(line) + 1); ++i) print line }' > "$tmp/big.yaml"
run big_yaml "is more than the 8 MiB a YAML job may have" --job "$tmp/big.yaml"

# 3. Duplicate keys: job, config, defect set.
printf 'name: t\npolylines:\n  - {type: mark, speed: 1, power: 100, speed: 2, points: [[0, 0], [0.001, 0]]}\n' \
  > "$tmp/dup_job.yaml"
run dup_job "dup_job.yaml:3:40: duplicate key 'polylines[0].speed' (first at line 3)" --job "$tmp/dup_job.yaml"
printf 'nc:\n  period_s: 1.0e-5\n  fir_t1_s: 300e-6\n  period_s: 2.0e-5\n' > "$tmp/dup_config.yaml"
run dup_config "dup_config.yaml:4:3: duplicate key 'nc.period_s' (first at line 2)" --job corner \
  --config "$tmp/dup_config.yaml"
printf 'name: dup\nmirror_x: {z: 0.01}\nmirror_x: {a: 0.02}\n' > "$tmp/dup_defects.yaml"
run dup_defect_set "dup_defects.yaml:3:1: duplicate key 'mirror_x' (first at line 2)" --job corner \
  --set "optics.defects=$tmp/dup_defects.yaml"

# 4. Correction tables: 2049 nodes declared in a 300-byte file; a half width of 1e300 m.
table_head='# scanhead correction table v1'
columns='columns i j q_x_rad q_y_rad dq_x_dx dq_y_dx dq_x_dy dq_y_dy d2q_x_dxdy d2q_y_dxdy'
printf '%s\nnodes 2049\nhalf_width_m 0.1\n%s\n0 0 0 0 0 0 0 0 0 0\n' "$table_head" "$columns" > "$tmp/table_2049.txt"
expect_error table_2049_nodes "table_2049.txt:2: nodes 2049 needs 2049² node lines" scanhead_table \
  --load "$tmp/table_2049.txt"
printf '%s\nnodes 2\nhalf_width_m 1e300\n%s\n0 0 0 0 0 0 0 0 0 0\n' "$table_head" "$columns" > "$tmp/table_wide.txt"
expect_error table_half_width "table_wide.txt:3: half_width_m must be in (0, 1] m" scanhead_table \
  --load "$tmp/table_wide.txt"

# 5. A CLI file declaring a billion layers in 80 bytes.
printf '$$HEADERSTART\n$$ASCII\n$$UNITS/1\n$$LAYERS/1000000000\n$$HEADEREND\n$$GEOMETRYSTART\n$$LAYER/0\n$$HATCHES/1,1,0,0,1,0\n$$GEOMETRYEND\n' \
  > "$tmp/layers.cli"
run cli_layers "layers.cli:4: \$\$LAYERS/1000000000 declares more layers than the file can hold" --job "$tmp/layers.cli"

# 6. A self-intersecting outline (a bow tie) as the fills' polygon file.
printf '0 0\n0.004 0.004\n0.004 0\n0 0.002\n' > "$tmp/bow_tie.txt"
run polygon_crossing "bow_tie.txt:3: the outline crosses itself: ring 1 edge lines 1-2 and ring 1 edge lines 3-4" \
  --job meander --set "cam.shape_file=$tmp/bow_tie.txt"

# 7. Tool options whose work grows as their square.
expect_error table_probes "--probes: must be an integer in [2, 2049] (got '1000000')" scanhead_table --probes 1000000
expect_error optics_grid "--grid: must be an integer in [2, 201] (got '100000')" scanhead_optics calibrate --grid 100000

if [ $failures -ne 0 ]; then
  echo "bad_files: $failures case(s) failed"
  exit 1
fi
echo "bad_files: all cases give a clear error within ${max_s} s and 1 GiB, nothing left behind"

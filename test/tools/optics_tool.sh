#!/usr/bin/env bash
# scanhead_optics: trace at (0, 0) on the nominal machine hits O_p = (0, 0); inverse∘trace is the
# identity on opt_table2; the generated URDF is the defective machine (parses, defect joints
# written, and the model read back from it traces the same spots) and is the package URDF itself
# for the nominal set; the residual of the nominal table on opt_table2 is the defects' ~0.26 mm,
# the machine's own table ~4.19 µm (bilinear); bad arguments fail with a message.
set -euo pipefail
tool=${1:-scanhead_optics}
src=$(cd "$(dirname "$0")/../.." && pwd)
urdf="$src/urdf/scanhead.urdf"
tmp=$(mktemp -d /tmp/scanhead_optics.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
py() { /usr/bin/python3 -c "$@"; }
fail() { echo "FAIL $1"; shift; printf '%s\n' "$@"; exit 1; }

# trace: O_p is the origin of the nominal work plane (urdf/scanhead.urdf: the beam reaches the
# base origin along -z at (0, 0)); 1e-12 m covers the rounding of the 45° mirror frames (~3e-16).
out=$("$tool" trace 0 0)
py "import sys; x, y, z = map(float, '$out'.split()); sys.exit(0 if abs(x) < 1e-12 and abs(y) < 1e-12 and z == 0 else 1)" \
  || fail "trace 0 0 on nominal: '$out' is not (0, 0, 0)"
out=$("$tool" trace --defects nominal 0.1 -0.05)
py "import sys; x, y, z = map(float, '$out'.split()); sys.exit(0 if 0.13 < x < 0.16 and -0.08 < y < -0.06 else 1)" \
  || fail "trace 0.1 -0.05: '$out' is not near (0.145, -0.070) (dx/dθx ≈ 1.44 m/rad, dy/dθy ≈ 1.40 m/rad)"

# inverse∘trace on opt_table2: within 1e-9 rad (Newton stops at 1e-12 m, i.e. ~1e-12 rad).
for q in "0 0" "0.1 -0.05" "-0.12 0.11" "0.03 0.12"; do
  spot=$("$tool" trace --defects opt_table2 $q)
  back=$("$tool" inverse --defects opt_table2 $(cut -d' ' -f1,2 <<<"$spot"))
  py "import sys; a = list(map(float, '$q'.split())); b = list(map(float, '$back'.split())); sys.exit(0 if max(abs(u - v) for u, v in zip(a, b)) < 1e-9 else 1)" \
    || fail "inverse(trace($q)) = $back on opt_table2"
done
# The defects move the spot: opt_table2 differs from nominal at (0, 0) by ~0.1 mm (OPT fig. 6).
a=$("$tool" trace --defects opt_table2 0 0)
py "import sys; x, y, z = map(float, '$a'.split()); d = (x * x + y * y) ** 0.5; sys.exit(0 if 20e-6 < d < 1e-3 else 1)" \
  || fail "opt_table2 spot at (0, 0) = $a: expected an offset of 20 µm .. 1 mm"

# urdf: the nominal set gives the package URDF byte for byte (zero origins, as written there).
"$tool" urdf --defects nominal --set optics.urdf_path="$urdf" > "$tmp/nominal.urdf"
cmp -s "$tmp/nominal.urdf" "$urdf" || fail "urdf --defects nominal differs from $urdf" "$(diff "$tmp/nominal.urdf" "$urdf" | head)"
"$tool" urdf --defects opt_table2 --set optics.urdf_path="$urdf" > "$tmp/opt.urdf"
py "
import sys, xml.etree.ElementTree as ET
root = ET.parse('$tmp/opt.urdf').getroot()
joints = {j.get('name'): j for j in root.findall('joint')}
for e in ['laser_source', 'galvo_x_mount', 'mirror_x', 'galvo_y_mount', 'mirror_y', 'window_1', 'window_2', 'work_plane']:
    o = joints[e + '_defect_joint'].find('origin')
    values = [float(v) for v in o.get('xyz').split() + o.get('rpy').split()]
    if not any(values) or max(abs(v) for v in values) > 1e-4:
        sys.exit('%s_defect_joint origin %s: expected non-zero values within 0.1 mm / 0.1 mrad' % (e, values))
" || fail "urdf --defects opt_table2: defect joints"
[ "$(grep -c '<joint ' "$tmp/opt.urdf")" = "$(grep -c '<joint ' "$urdf")" ] || fail "urdf: joint count changed"
# The model read back from the generated URDF is the defective machine (same spots within 1e-12 m).
for q in "0 0" "0.1 -0.05" "-0.15 0.15"; do
  a=$("$tool" trace --defects opt_table2 $q)
  b=$("$tool" trace --defects nominal --set optics.urdf_path="$tmp/opt.urdf" $q)
  py "import sys; a = list(map(float, '$a'.split())); b = list(map(float, '$b'.split())); sys.exit(0 if max(abs(u - v) for u, v in zip(a, b)) < 1e-12 else 1)" \
    || fail "trace $q: opt_table2 applied '$a' vs from the generated URDF '$b'"
done
# Random sets and files are accepted the same way.
"$tool" urdf --defects random:seed=3 | grep -q 'mirror_y_defect_joint' || fail "urdf --defects random:seed=3"
"$tool" trace --defects "$src/config/defects/opt_table2.yaml" 0.1 -0.05 > "$tmp/file.txt"
[ "$(cat "$tmp/file.txt")" = "$("$tool" trace --defects opt_table2 0.1 -0.05)" ] || fail "file vs built-in opt_table2"

# residual: the nominal table on opt_table2 is off by the defects (~264 µm), the machine's own
# table only by its interpolation (bilinear ~4.19 µm, bicubic < 1 µm).
out=$("$tool" residual --defects opt_table2 --probes 65)
value() { sed -n "s/^$1: {max_error_m: \([^,]*\),.*/\1/p" <<<"$out"; }
for key in defects nodes interpolation probes_per_axis nominal_table own_table; do
  grep -q "^$key:" <<<"$out" || fail "residual: no $key" "$out"
done
py "import sys; n = float('$(value nominal_table)'); o = float('$(value own_table)'); sys.exit(0 if n > 50e-6 and o < 5e-6 else 1)" \
  || fail "residual bilinear: nominal_table max > 50 µm and own_table max < 5 µm expected" "$out"
out=$("$tool" residual --defects opt_table2 --probes 65 --interpolation bicubic --nodes 33)
py "import sys; n = float('$(value nominal_table)'); o = float('$(value own_table)'); sys.exit(0 if n > 50e-6 and o < 1e-6 else 1)" \
  || fail "residual bicubic: nominal_table max > 50 µm and own_table max < 1 µm expected" "$out"

# Errors: "scanhead_optics: error: ..." and exit 1.
expect_error() {  # pattern, arguments...
  local pattern=$1
  shift
  if "$tool" "$@" > "$tmp/out" 2> "$tmp/err"; then fail "accepted: $*" "$(cat "$tmp/out")"; fi
  grep -q "^scanhead_optics: error: " "$tmp/err" || fail "no error prefix: $*" "$(cat "$tmp/err")"
  grep -q -- "$pattern" "$tmp/err" || fail "message for '$*' lacks '$pattern'" "$(cat "$tmp/err")"
}
expect_error "unknown command 'spot' (commands: trace, inverse, urdf, residual" spot 0 0
expect_error "no command" --defects opt_table2
expect_error "THETA_Y: must be a finite number (got 'abc')" trace 0 abc
expect_error "THETA_X: must be a finite number (got 'nan')" trace nan 0
expect_error "THETA_Y is required (trace takes THETA_X THETA_Y)" trace 0.1
expect_error "not reachable" inverse 0.5 0
expect_error "unknown defect set 'typical'" trace --defects typical 0 0
expect_error "random:seed=N" trace --defects random:seed=x 0 0
expect_error "missing.yaml: cannot open" trace --defects "$tmp/missing.yaml" 0 0
expect_error "--nodes is not an option of trace" trace --nodes 9 0 0
expect_error "--seed: must be an integer" calibrate --seed 1.5
expect_error "--grid: must be an integer in .2, 201. (got '100000')" calibrate --grid 100000
expect_error "--probes: must be an integer in .2, 2049. (got '1e7')" residual --probes 1e7
expect_error "outside the galvos" trace 0.5 0
expect_error "--interpolation must be bilinear or bicubic" residual --interpolation cubic
expect_error "unknown argument '--bogus'" urdf --bogus
printf 'mirror_x: {x: 0.1}\n' > "$tmp/bad.yaml"
expect_error "bad.yaml:1: unknown component 'mirror_x.x'" urdf --defects "$tmp/bad.yaml"
echo "scanhead_optics: trace, inverse, urdf, residual and errors ok"

#!/usr/bin/env bash
# scanhead_job and the job formats end to end: stats keys, CLI conversion round trip through the
# tool (ASCII and binary), the segment example, the squares job's recipes, pictures, errors.
set -euo pipefail
tool=${1:-scanhead_job}
segment=${2:-../shared/data/segment_path_L.txt}
tmp=$(mktemp -d /tmp/scanhead_job.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
value() { sed -n "s/^$1: //p" <<<"$2"; }
fail() { echo "FAIL $*"; exit 1; }

stats=$("$tool" stats "$segment")
for key in mark_length_m jump_length_m ideal_time_s; do grep -q "^$key:" <<<"$stats" || fail "stats: no $key"; done
# The adamantine L: 2 mm + 1.8 mm at 0.8 m/s.
/usr/bin/python3 -c "import sys; L=float('$(value mark_length_m "$stats")'); t=float('$(value mark_time_s "$stats")'); sys.exit(0 if abs(L-0.0038)<1e-12 and abs(t-0.0038/0.8)<1e-12 else 1)" \
  || fail "segment example: $(value mark_length_m "$stats") m in $(value mark_time_s "$stats") s"

# CLI round trip through the tool: the same marked length within the CLI unit (1 µm here).
"$tool" convert hatch:size=0.004,spacing=0.0002 --out "$tmp/h.yaml" > /dev/null
"$tool" convert "$tmp/h.yaml" --out "$tmp/h.cli" --units-mm 0.001 > /dev/null
"$tool" convert "$tmp/h.yaml" --out "$tmp/hb.cli" --binary --units-mm 0.001 > /dev/null
ref=$(value mark_length_m "$("$tool" stats "$tmp/h.yaml")")
for f in h.cli hb.cli; do
  got=$(value mark_length_m "$("$tool" stats "$tmp/$f")")
  /usr/bin/python3 -c "import sys; sys.exit(0 if abs($got-$ref) < 1e-6 else 1)" || fail "$f: mark length $got vs $ref"
done

# THESIS squares: recipe 1 / recipe 2 time per square = the recipes' speed mix (checked in gtest);
# here: both run, recipe 2 is faster, recipe 3 is exactly twice as fast as recipe 2.
t1=$(value ideal_time_s "$("$tool" stats squares:recipe=1,rows=2,columns=2)")
t2=$(value ideal_time_s "$("$tool" stats squares:recipe=2,rows=2,columns=2)")
t3=$(value ideal_time_s "$("$tool" stats squares:recipe=3,rows=2,columns=2)")
/usr/bin/python3 -c "import sys; sys.exit(0 if $t1 > $t2 and abs($t2 - 2*$t3) < 1e-9*$t2 else 1)" || fail "recipes: $t1 $t2 $t3"

"$tool" picture chessboard:size=0.01,island=0.0025 --out "$tmp/c.png" > /dev/null
[ "$(head -c 4 "$tmp/c.png" | tail -c 3)" = "PNG" ] || fail "picture is not a PNG"
if "$tool" stats "$tmp/missing.cli" 2> "$tmp/err"; then fail "missing file accepted"; fi
grep -q "missing.cli" "$tmp/err" || fail "error does not name the file: $(cat "$tmp/err")"
echo "scanhead_job: stats, convert (CLI ASCII/binary), segment, squares, picture ok"

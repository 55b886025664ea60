#!/usr/bin/env bash
# Byte-identity guard: the batch runner's metrics.yaml, energy_map.tiff and trace.csv for a fixed set
# of jobs (the built-in corner and hatch, the THESIS squares with recipe thesis1, and the option sets of
# test/ros/options_graph_batch.sh) must match the SHA-256 sums in golden_outputs.sha256.
# A change that moves a figure on purpose regenerates the sums (--update) and says why in its commit.
#   test/golden/golden_outputs.sh [scanhead_run] [--update]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
run=scanhead_run update=false
for a in "$@"; do
  case $a in --update) update=true;; *) run=$a;; esac
done
sums="$here/golden_outputs.sha256"
tmp=$(mktemp -d /tmp/scanhead_golden.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
cases=(
  "corner|corner"
  "hatch|hatch"
  "squares|squares:rows=2,columns=2|recipe.preset=thesis1"
  "filters|corner:speed=2,angle=90|nc.igt.mode=table nc.igt.table_interpolation=bicubic nc.filter_mode=adaptive nc.power_mode=speed nc.quantisation_bits=18"
  "defects|corner:speed=2,angle=90|optics.defects=opt_table2 nc.igt.mode=table"
  "timing|squares:recipe=1,rows=1,columns=1,spacing=0.003|recipe.preset=thesis1 nc.skywriting.enabled=true nc.mark_delay_s=100e-6 nc.jump_delay_s=250e-6 nc.polygon_delay_s=40e-6 nc.polygon_delay_mode=angle nc.cap_speeds=true nc.power_mode=predicted nc.igt.mode=table"
  "layer|squares:recipe=2,rows=1,columns=1,side=0.004|energy.defocus_mode=field energy.tile_cache_bytes=1048576 thermal.enabled=true thermal.duration_s=0.004 energy.crop_regions=-0.001,-0.001,0.001,0.001,centre"
)
for c in "${cases[@]}"; do
  IFS='|' read -r name job settings <<<"$c"
  set_args=()
  for s in $settings; do set_args+=(--set "$s"); done
  "$run" --job "$job" --out "$tmp/$name" --quiet "${set_args[@]}"
done
(cd "$tmp" && sha256sum */metrics.yaml */energy_map.tiff */trace.csv | sort -k2) > "$tmp/actual.sha256"
if $update; then
  cp "$tmp/actual.sha256" "$sums"
  echo "wrote $sums"
  exit 0
fi
if ! diff "$sums" "$tmp/actual.sha256"; then
  echo "FAIL: outputs differ from test/golden/golden_outputs.sha256 (lines above: < expected, > now)"
  exit 1
fi
echo "golden outputs: $(wc -l < "$sums") files byte-identical"

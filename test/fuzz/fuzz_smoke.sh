#!/usr/bin/env bash
# Fuzz smoke pass: builds each libFuzzer target (clang++, -fsanitize=fuzzer,address,undefined)
# against the core sources it needs, then runs it briefly on a copy of its seed corpus.
# Exits non-zero on any crash, sanitizer report, leak or timeout (libFuzzer's own exit codes),
# 77 if clang++ with libFuzzer is not available (register with SKIP_RETURN_CODE 77 if wanted).
#
# Usage: test/fuzz/fuzz_smoke.sh [target ...]
#   targets: cli segment yaml_job config defect_set correction_table polygon (default: all)
# Environment: FUZZ_CXX (default clang++), FUZZ_RUNS (default 20000 executions per target),
#              FUZZ_BUILD_DIR (default: a fresh temporary directory, removed on success).
# Long campaigns: build as below, then e.g. ./fuzz_cli -runs=10000000 -jobs=1 -max_len=4096 corpus/
# (FUZZ_BUILD_DIR keeps the binaries).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
CXX=${FUZZ_CXX:-clang++}
RUNS=${FUZZ_RUNS:-20000}
if [[ -n "${FUZZ_BUILD_DIR:-}" ]]; then
  BUILD=$FUZZ_BUILD_DIR
  mkdir -p "$BUILD"
  KEEP=1
else
  BUILD=$(mktemp -d "${TMPDIR:-/tmp}/scanhead_fuzz.XXXXXX")
  KEEP=0
fi

CXXFLAGS=(-std=c++17 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
          -fno-omit-frame-pointer -I"$ROOT/include" -I/usr/include/eigen3)

ALL_TARGETS=(cli segment yaml_job config defect_set correction_table polygon)

# Core sources each target needs (the reader and what it calls).
sources_for() {
  local s="$ROOT/src"
  case "$1" in
    cli) echo "$s"/job/formats/cli_*.cpp "$s/job/file_survey.cpp" "$s/job/job_placement.cpp" \
      "$s/common/config_check.cpp" "$s/common/number_text.cpp" ;;
    segment) echo "$s/job/formats/segment_path.cpp" "$s/job/file_survey.cpp" "$s/job/job_placement.cpp" \
      "$s/common/config_check.cpp" "$s/common/number_text.cpp" ;;
    yaml_job) echo "$s/job/formats/job_io.cpp" "$s/job/job_placement.cpp" "$s/common/yaml_document.cpp" \
      "$s/common/number_text.cpp" ;;
    config)  # config_io and every validate() it calls
      echo "$s/chain/config_io.cpp" "$s/common/config_check.cpp" "$s/common/number_text.cpp" \
        "$s/common/yaml_document.cpp" "$s/energy/energy_config.cpp" "$s/energy/map_regions.cpp" \
        "$s/job/cam_config.cpp" "$s/job/recipe.cpp" "$s/job/job_stats.cpp" "$s/job/path_timeline.cpp" \
        "$s/job/generators/thesis_square_job.cpp" "$s/nc/nc_config.cpp" "$s/optics/optics_config.cpp" \
        "$s/servo/servo_config.cpp" "$s/servo/cascade_gains.cpp" "$s/servo/galvo_plant.cpp" \
        "$s/servo/foh_discretisation.cpp" "$s/servo/hinf/hinf_config.cpp" "$s/thermal/thermal_config.cpp" ;;
    defect_set) echo "$s/optics/defect_set_io.cpp" "$s/optics/defect_catalog.cpp" "$s/common/yaml_document.cpp" \
      "$s/common/number_text.cpp" ;;
    correction_table) echo "$s/optics/correction_table.cpp" "$s/common/number_text.cpp" ;;
    polygon) echo "$s/job/generators/shape_file.cpp" "$s/job/generators/shape.cpp" "$s/common/config_check.cpp" \
      "$s/common/number_text.cpp" ;;
    *) echo "unknown fuzz target '$1' (expected: ${ALL_TARGETS[*]})" >&2; return 1 ;;
  esac
}

# Libraries (yaml-cpp, uninstrumented: the targets fuzz our walk over its tree) and input sizes: a
# config seed is the shipped 16 KB config/scanhead.yaml.
libs_for() {
  case "$1" in
    yaml_job | config | defect_set) echo "-lyaml-cpp" ;;
  esac
}
max_len_for() {
  case "$1" in
    config) echo 20480 ;;
    *) echo 4096 ;;
  esac
}

if ! command -v "$CXX" > /dev/null; then
  echo "fuzz_smoke: $CXX not found: skipped" >&2
  exit 77
fi
if ! echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' |
     "$CXX" -x c++ -fsanitize=fuzzer - -o "$BUILD/probe" 2> /dev/null; then
  echo "fuzz_smoke: $CXX cannot link -fsanitize=fuzzer (libFuzzer missing): skipped" >&2
  exit 77
fi

TARGETS=("$@")
[[ ${#TARGETS[@]} -eq 0 ]] && TARGETS=("${ALL_TARGETS[@]}")

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
status=0
for t in "${TARGETS[@]}"; do
  srcs=$(sources_for "$t")
  for s in $srcs; do
    [[ -f "$s" ]] || { echo "fuzz_smoke: missing source $s" >&2; exit 1; }
  done
  echo "== fuzz_$t: building"
  # shellcheck disable=SC2086
  "$CXX" "${CXXFLAGS[@]}" "$ROOT/test/fuzz/fuzz_$t.cpp" $srcs $(libs_for "$t") -o "$BUILD/fuzz_$t"
  corpus="$BUILD/corpus_$t"
  rm -rf "$corpus"
  mkdir -p "$corpus"
  find "$ROOT/test/fuzz/corpus_$t" -type f ! -name 'README*' -exec cp {} "$corpus/" \;
  echo "== fuzz_$t: $RUNS runs on $(ls "$corpus" | wc -l) seeds"
  if ! "$BUILD/fuzz_$t" -runs="$RUNS" -max_len="$(max_len_for "$t")" -timeout=10 -rss_limit_mb=2048 -seed=1 \
       -artifact_prefix="$BUILD/crash_${t}_" -print_final_stats=1 "$corpus"; then
    echo "fuzz_smoke: fuzz_$t FAILED; reproducer(s) in $BUILD" >&2
    status=1
    KEEP=1
  fi
done
[[ $KEEP -eq 0 ]] && rm -rf "$BUILD"
exit $status

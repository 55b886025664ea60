#!/usr/bin/env bash
# Installs the dependencies, builds, and runs the whole test suite (gtest + rostest).
# Fails if any test fails or if no test ran.
set -euo pipefail
cd "$(dirname "$0")"
# The tests also build the benchmarks (so they keep compiling), with warnings as errors, and run the
# fuzz smoke pass.
export SCANHEAD_CMAKE_ARGS="-DSCANHEAD_BUILD_BENCHMARKS=ON -DSCANHEAD_BUILD_FUZZERS=ON -DSCANHEAD_WERROR=ON"
. scripts/prepare.sh
# A master port of our own, so two runs (or a running virtual machine) never collide.
export ROS_MASTER_URI="http://127.0.0.1:$((20000 + $$ % 10000))"
rm -rf build/scanhead/test_results
if ! colcon test --event-handlers console_direct- --return-code-on-test-failure --ctest-args --output-on-failure; then
  colcon test-result --verbose --test-result-base build/scanhead/test_results || true
  echo "FAILED tests:"
  grep -E '\*\*\*(Failed|Timeout|Exception)' log/latest_test/scanhead/stdout_stderr.log || true
  echo "full output: log/latest_test/scanhead/stdout_stderr.log"
  exit 1
fi
summary=$(colcon test-result --verbose --test-result-base build/scanhead/test_results)
echo "$summary"
count=$(sed -n 's/^Summary: \([0-9]*\) tests.*/\1/p' <<<"$summary")
echo "gtest/rostest cases run: ${count:-0} (plus the CTest script tests above)"
[ "${count:-0}" -gt 0 ] || { echo "no test ran" >&2; exit 1; }

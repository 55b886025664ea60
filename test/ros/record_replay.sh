#!/usr/bin/env bash
# Live graph with record:=true, bag replay, and batch run: the three metrics.yaml are identical.
# Registered with CTest (see CMakeLists.txt); needs the installed package on the environment.
set -euo pipefail
run=${1:-scanhead_run}
launch_dir="$(cd "$(dirname "$0")/../../launch" && pwd)"  # full paths: the package may be found twice
tmp=$(mktemp -d /tmp/scanhead_replay.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
job="corner:speed=2,angle=53.13"
export ROS_IP=127.0.0.1
export ROS_MASTER_URI="http://127.0.0.1:$((30000 + $$ % 10000))"
timeout 180 roslaunch "$launch_dir/virtual_machine.launch" job:="$job" out:="$tmp/graph" record:=true bag:="$tmp/run.bag" \
  > "$tmp/graph.log" 2>&1 || { cat "$tmp/graph.log"; exit 1; }
timeout 180 roslaunch "$launch_dir/replay.launch" bag:="$tmp/run.bag" out:="$tmp/replay" > "$tmp/replay.log" 2>&1 \
  || { cat "$tmp/replay.log"; exit 1; }
"$run" --job "$job" --out "$tmp/batch" --quiet
for run in graph replay; do
  if ! cmp "$tmp/batch/metrics.yaml" "$tmp/$run/metrics.yaml"; then
    diff "$tmp/batch/metrics.yaml" "$tmp/$run/metrics.yaml" || true
    echo "FAIL: $run metrics differ from the batch run"
    exit 1
  fi
done
grep -q "^dropped_samples: 0$" "$tmp/graph/metrics.yaml"
echo "graph, replay and batch metrics.yaml are identical"

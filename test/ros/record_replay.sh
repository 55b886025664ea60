#!/usr/bin/env bash
# Live graph with record:=true, bag replay, and batch run: the three metrics.yaml are identical,
# with the stages as nodelets and as separate nodes.
# Registered with CTest (see CMakeLists.txt); needs the installed package on the environment.
set -euo pipefail
run=${1:-scanhead_run}
launch_dir="$(cd "$(dirname "$0")/../../launch" && pwd)"  # full paths: the package may be found twice
tmp=$(mktemp -d /tmp/scanhead_replay.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
job="corner:speed=2,angle=53.13"
export ROS_IP=127.0.0.1
export ROS_MASTER_URI="http://127.0.0.1:${SCANHEAD_ROS_PORT:-$((30000 + $$ % 10000))}"  # SCANHEAD_ROS_PORT: a fixed port
"$run" --job "$job" --out "$tmp/batch" --quiet
# The stages as nodelets in one manager (the default), then each its own node; the bag recorded with
# nodelets is replayed by separate nodes and the other way round.
for mode in true:false false:true; do
  live=${mode%:*} replay=${mode#*:}
  timeout 180 roslaunch "$launch_dir/virtual_machine.launch" job:="$job" out:="$tmp/graph-$live" record:=true \
    bag:="$tmp/run-$live.bag" nodelets:="$live" > "$tmp/graph-$live.log" 2>&1 || { cat "$tmp/graph-$live.log"; exit 1; }
  timeout 180 roslaunch "$launch_dir/replay.launch" bag:="$tmp/run-$live.bag" out:="$tmp/replay-$replay" \
    nodelets:="$replay" > "$tmp/replay-$replay.log" 2>&1 || { cat "$tmp/replay-$replay.log"; exit 1; }
  for run in "graph-$live" "replay-$replay"; do
    if ! cmp "$tmp/batch/metrics.yaml" "$tmp/$run/metrics.yaml"; then
      diff "$tmp/batch/metrics.yaml" "$tmp/$run/metrics.yaml" || true
      echo "FAIL: $run (nodelets:=${run#*-}) metrics differ from the batch run"
      exit 1
    fi
  done
  grep -q "^dropped_samples: 0$" "$tmp/graph-$live/metrics.yaml"
  # A job done ends the launch as Ctrl-C does (exit 0 above): "done, results in", no red "REQUIRED process" banner.
  for log in "graph-$live" "replay-$replay"; do
    grep -q "scanhead: done, results in $tmp/$log" "$tmp/$log.log" || { echo "FAIL: $log: no 'done' line"; exit 1; }
    if grep -q "REQUIRED process" "$tmp/$log.log"; then echo "FAIL: $log ended with the required-node banner"; exit 1; fi
  done
  echo "nodelets:=$live graph, nodelets:=$replay replay and batch metrics.yaml are identical"
done

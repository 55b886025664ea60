#!/usr/bin/env bash
# Installs the dependencies, builds, and runs the virtual scan head (node graph) on a job.
#   ./run_virtual_machine.sh                      # built-in corner job → results/corner/
#   ./run_virtual_machine.sh job:=my_job.yaml out:=results/mine rviz:=true
set -euo pipefail
cd "$(dirname "$0")"
. scripts/prepare.sh
export ROS_MASTER_URI="${ROS_MASTER_URI:-http://127.0.0.1:11311}"
args=("$@")
printf '%s\n' "${args[@]}" | grep -q '^out:=' || args+=("out:=results/corner")
out=$(printf '%s\n' "${args[@]}" | sed -n 's/^out:=//p' | tail -n 1)
[[ "$out" = /* ]] || out="$PWD/$out"
# roslaunch (ROS 1.15) exits 0 even when a required node failed: the exit status of this script
# says whether this run published a complete results folder.
stamp=$(mktemp "${TMPDIR:-/tmp}/scanhead_vm.XXXXXX")
trap 'rm -f "$stamp"' EXIT
status=0
roslaunch scanhead virtual_machine.launch "${args[@]}" || status=$?
if [[ $status -ne 0 ]]; then
  echo "run_virtual_machine: roslaunch failed (exit $status)" >&2
  exit "$status"
fi
if [[ ! "$out/metrics.yaml" -nt "$stamp" ]]; then
  echo "run_virtual_machine: error: the graph wrote no results to $out (see the log above)" >&2
  exit 1
fi
if grep -q '^complete: false' "$out/metrics.yaml"; then
  echo "run_virtual_machine: error: the job did not complete; $out holds what arrived" \
    "(metrics.yaml: dropped_samples, stream_gap)" >&2
  exit 1
fi
echo "run_virtual_machine: done, results in $out"

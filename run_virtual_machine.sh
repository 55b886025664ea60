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
exec roslaunch scanhead virtual_machine.launch "${args[@]}"

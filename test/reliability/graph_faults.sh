#!/usr/bin/env bash
# Faults in the node graph (issue 14, "a graph that survives a dead stage"), replayed:
#  1. kill -9 of galvo_servo mid-job (stages as nodes): the energy node sees its stream stall,
#     writes what arrived as an incomplete result (metrics.yaml complete: false, dropped_samples > 0,
#     stream_gap) and exits 1; the launch ends within a bounded time. The same with the stages as
#     nodelets (kill -9 of galvo_servo's loader): the launch ends in bounded time with either the
#     complete result or an incomplete one, never hangs.
#  2. a plain subscriber on /nc/setpoint connected before the stages, N runs (default 20, both
#     modes in turn): every run completes with metrics.yaml byte-identical to the batch run.
#  3. rostopic echo works on every published topic of a running graph (python message packages).
#  4. a stage killed between jobs and respawned (respawn:=true) rejoins: the next job completes,
#     identical to the batch run.
#  5. a consumer the NC expects never comes: the NC gives the job up naming it (~ready_timeout_s),
#     the energy node fails the planned job (~start_timeout_s) and the launch ends, no results folder.
#  6. a slow but live stage: the energy node stopped (SIGSTOP) for 12 s mid-job, then continued
#     (SIGCONT): the stages upstream see no chunk for longer than stall_timeout_s and the NC's full
#     window no ack for longer than flow_timeout_s, ping the graph, find it alive and wait with a
#     warning; the job completes, metrics.yaml identical to the batch run, no stall.
#  7. a live stage that hangs: galvo_servo stopped (SIGSTOP) mid-job with hang_timeout_s:=5: its
#     XML-RPC port accepts and never answers (not gone), so the job is abandoned only after
#     hang_timeout_s, with an error naming it; incomplete result, exit 1.
# Registered with CTest (see CMakeLists.txt); needs the built package on the environment.
# Usage: graph_faults.sh [scanhead_run] ; SCANHEAD_FAULT_RUNS=N (case 2), SCANHEAD_FAULT_CASES="1 3"
# (a subset), SCANHEAD_ROS_PORT=P (the master's port).
set -euo pipefail
run=${1:-scanhead_run}
runs=${SCANHEAD_FAULT_RUNS:-20}
launch_dir="$(cd "$(dirname "$0")/../../launch" && pwd)"  # full paths: the package may be found twice
tmp=$(mktemp -d /tmp/scanhead_graph_faults.XXXXXX)
export ROS_IP=127.0.0.1
export ROS_MASTER_URI="http://127.0.0.1:${SCANHEAD_ROS_PORT:-$((11700 + $$ % 100))}"
export ROS_LOG_DIR="$tmp/ros_log"
background=()  # PIDs of what this script started and still runs
cleanup() {
  for pid in "${background[@]}"; do kill -INT "$pid" 2> /dev/null || true; done
  for pid in "${background[@]}"; do
    for _ in $(seq 150); do kill -0 "$pid" 2> /dev/null || break; sleep 0.2; done  # roslaunch stops its nodes (and master) in < 30 s
    kill -KILL "$pid" 2> /dev/null || true
  done
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}
started() {  # pid: remember a background process
  background+=("$1")
}
stopped() {  # pid: forget it (it ended)
  local kept=() p
  for p in "${background[@]}"; do [ "$p" = "$1" ] || kept+=("$p"); done
  background=("${kept[@]+"${kept[@]}"}")
}
wait_for() {  # seconds command...: polls until the command succeeds
  local deadline=$((SECONDS + $1))
  shift
  until "$@" > /dev/null 2>&1; do
    [ $SECONDS -lt $deadline ] || return 1
    sleep 0.2
  done
}
wait_exit() {  # seconds pid: waits for a background process to end; prints its run time
  local deadline=$((SECONDS + $1)) pid=$2
  while kill -0 "$pid" 2> /dev/null; do
    [ $SECONDS -lt $deadline ] || return 1
    sleep 0.1
  done
  wait "$pid" || true
  stopped "$pid"
}
node_pid() {  # node name: its process id, as the node tells the master
  rosnode info "$1" 2> /dev/null | sed -n 's/^Pid: //p'
}
now() { date +%s.%N; }
want() { [[ " ${SCANHEAD_FAULT_CASES:-1 2 3 4 5 6 7} " == *" $1 "* ]]; }
job="corner:speed=2,angle=90"
"$run" --job "$job" --out "$tmp/batch" --quiet
elapsed() { awk -v a="$(now)" -v b="$1" 'BEGIN { printf "%.1f", a - b }'; }

# ---- 1. kill -9 of a stage mid-job -------------------------------------------------------------
job_long="corner:speed=0.0002,angle=90"  # 4 M samples: ~10 s in the graph, ~4 s in batch
# The kill of a separate galvo_servo must land while the servo still has work: 16 M samples, so a
# loaded machine (rostopic's python start-up is seconds there) cannot let the job's upstream finish
# first. Only the nodelet case runs such a job to its end, and it keeps the shorter one.
job_kill="corner:speed=0.00005,angle=90"
acked() {  # the energy node acknowledged samples of a job
  local n
  n=$(timeout 5 rostopic echo -n 1 /energy/ack/next_index 2> /dev/null | head -1)
  [ -n "$n" ] && [ "$n" -gt 0 ]
}
kill_mid_job() {  # nodelets
  local mode=$1 dir="$tmp/kill-$1" log="$tmp/kill-$1.log"
  local job=$job_long
  [ "$mode" = false ] && job=$job_kill
  roslaunch "$launch_dir/virtual_machine.launch" job:="$job" out:="$dir" nodelets:="$mode" > "$log" 2>&1 &
  local launch_pid=$!
  started $launch_pid
  # Mid-job: the energy node has acknowledged samples (energy/ack, latched).
  wait_for 90 acked || { cat "$log"; fail "kill ($mode): the job never started"; }
  local victim
  victim=$(node_pid /galvo_servo)
  [ -n "$victim" ] || fail "kill ($mode): no pid for /galvo_servo"
  grep -q "energy: job 1 done" "$log" && fail "kill ($mode): the job ended before the kill (make it longer)"
  kill -9 "$victim"
  [ "$mode" = false ] && grep -q "nc: job 1 done" "$log" &&
    fail "kill ($mode): the NC had sent the whole job before the kill (make \$job_kill longer)"
  local t0
  t0=$(now)
  wait_exit 60 $launch_pid || { cat "$log"; fail "kill ($mode): the launch still runs 60 s after kill -9 of galvo_servo"; }
  local took
  took=$(elapsed "$t0")
  if [ "$mode" = false ]; then
    # A separate process died: the stream must stall and the result must say so.
    grep -q "energy: job 1 stalled" "$log" || { cat "$log"; fail "kill ($mode): the energy node did not report the stall"; }
    grep -q "REQUIRED process \[energy_accumulator-" "$log" && grep -q "exit code 1, cmd [^ ]*/energy_accumulator " "$log" ||
      { cat "$log"; fail "kill ($mode): the energy node did not end the launch with exit code 1"; }
    [ -f "$dir/metrics.yaml" ] || fail "kill ($mode): no results folder written"
    grep -q "^complete: false$" "$dir/metrics.yaml" || fail "kill ($mode): metrics.yaml does not say complete: false"
    grep -q "^stream_gap: {streams: \"/optics/spot" "$dir/metrics.yaml" || fail "kill ($mode): metrics.yaml has no stream_gap"
    local dropped
    dropped=$(sed -n 's/^dropped_samples: //p' "$dir/metrics.yaml")
    [ "$dropped" -gt 0 ] || fail "kill ($mode): dropped_samples is $dropped"
    echo "kill -9 galvo_servo mid-job (nodes): launch ended $took s after the kill; incomplete result," \
      "dropped_samples $dropped; $(grep '^stream_gap' "$dir/metrics.yaml")"
  else
    # The nodelet runs in the manager: killing its loader unloads it (bond) or leaves it running.
    if [ -f "$dir/metrics.yaml" ] && grep -q "^complete: false$" "$dir/metrics.yaml"; then
      echo "kill -9 galvo_servo loader mid-job (nodelets): launch ended $took s after the kill;" \
        "incomplete result, dropped_samples $(sed -n 's/^dropped_samples: //p' "$dir/metrics.yaml")"
    elif [ -f "$dir/metrics.yaml" ]; then
      grep -q "^dropped_samples: 0$" "$dir/metrics.yaml" || fail "kill ($mode): a complete result with dropped samples"
      echo "kill -9 galvo_servo loader mid-job (nodelets): the nodelet kept running; launch ended" \
        "$took s after the kill with the complete result"
    else
      cat "$log"
      fail "kill ($mode): the launch ended without a results folder"
    fi
  fi
  awk -v t="$took" 'BEGIN { exit !(t < 30) }' || fail "kill ($mode): the launch took $took s to end"
}
if want 1; then
  kill_mid_job false
  kill_mid_job true
fi

# ---- 2. an early plain subscriber ---------------------------------------------------------------
if want 2; then
roscore -p "${ROS_MASTER_URI##*:}" > "$tmp/roscore.log" 2>&1 &
core_pid=$!
started $core_pid
wait_for 30 rostopic list || fail "no ROS master"
# Connected before any stage exists: the NC starts after it, and every run.
rostopic echo --noarr /nc/setpoint > /dev/null 2> "$tmp/echo.err" &
echo_pid=$!
started $echo_pid
t0=$(now)
for i in $(seq "$runs"); do
  mode=$([ $((i % 2)) = 1 ] && echo true || echo false)
  timeout 120 roslaunch "$launch_dir/virtual_machine.launch" job:="$job" out:="$tmp/sub-$i" nodelets:="$mode" \
    > "$tmp/sub-$i.log" 2>&1 || { cat "$tmp/sub-$i.log"; fail "early subscriber run $i (nodelets:=$mode) did not end"; }
  cmp -s "$tmp/batch/metrics.yaml" "$tmp/sub-$i/metrics.yaml" ||
    { cat "$tmp/sub-$i.log"; diff "$tmp/batch/metrics.yaml" "$tmp/sub-$i/metrics.yaml" || true;
      fail "early subscriber run $i (nodelets:=$mode): metrics differ from the batch run"; }
  rm -rf "$tmp/sub-$i"
done
kill -0 $echo_pid 2> /dev/null || { cat "$tmp/echo.err"; fail "rostopic echo /nc/setpoint died"; }
echo "early subscriber on /nc/setpoint: $runs of $runs runs complete, metrics.yaml identical to batch" \
  "($(elapsed "$t0") s)"
fi

# ---- 3. rostopic echo on every topic ------------------------------------------------------------
if want 3; then
roslaunch "$launch_dir/virtual_machine.launch" job:=/nonexistent/start_idle.yaml debug:=true \
  > "$tmp/echo-graph.log" 2>&1 &
graph_pid=$!
started $graph_pid
wait_for 60 bash -c "rostopic info /optics/spot | grep -q energy_accumulator || rostopic info /optics/spot | grep -q scanhead_manager" ||
  fail "the graph did not come up"
sleep 2
topics=$(rostopic list -p)
echo_pids=()
for t in $topics; do
  timeout 60 rostopic echo -n 1 --noarr "$t" > "$tmp/echo-$(echo "$t" | tr / _).out" 2>&1 &
  echo_pids+=("$!:$t")
done
sleep 3  # the echos connect
rostopic pub -1 /cam/load std_msgs/String "data: '$job'" > /dev/null
bad=""
for e in "${echo_pids[@]}"; do
  wait "${e%%:*}" || bad="$bad ${e#*:}"
done
for t in $bad; do cat "$tmp/echo-$(echo "$t" | tr / _).out"; done
[ -z "$bad" ] || fail "rostopic echo failed on:$bad"
echo "rostopic echo: one message on each of the $(echo $topics | wc -w) published topics:" $topics
kill -INT $graph_pid
wait_exit 30 $graph_pid || fail "the graph did not stop on SIGINT"
fi

# ---- 4. a stage killed between jobs rejoins the next one ---------------------------------------
if want 4; then
roslaunch "$launch_dir/virtual_machine.launch" job:="$job" nodelets:=false respawn:=true \
  > "$tmp/respawn.log" 2>&1 &
graph_pid=$!
started $graph_pid
metrics_of() {  # job id file: waits for that job's energy/metrics, writes its metrics_yaml
  # ROS's Python (rospy lives under /usr: the python3 first on PATH may be another one)
  timeout 60 /usr/bin/python3 - "$1" "$2" << 'EOF'
import sys, rospy
from scanhead.msg import JobMetrics
job_id, out = int(sys.argv[1]), sys.argv[2]
rospy.init_node("graph_faults_metrics", anonymous=True)
while not rospy.is_shutdown():
    m = rospy.wait_for_message("/energy/metrics", JobMetrics)
    if m.job_id == job_id:
        open(out, "w").write(m.metrics_yaml)
        break
EOF
}
metrics_of 1 "$tmp/respawn-1.yaml" || { cat "$tmp/respawn.log"; fail "respawn: job 1 never finished"; }
old=$(node_pid /galvo_servo)
kill -9 "$old"
wait_for 30 bash -c "p=\$(rosnode info /galvo_servo 2>/dev/null | sed -n 's/^Pid: //p'); [ -n \"\$p\" ] && [ \"\$p\" != $old ]" ||
  fail "respawn: galvo_servo did not come back"
t0=$(now)
rostopic pub -1 /cam/load std_msgs/String "data: '$job'" > /dev/null
metrics_of 2 "$tmp/respawn-2.yaml" || { cat "$tmp/respawn.log"; fail "respawn: job 2 never finished"; }
cmp "$tmp/batch/metrics.yaml" "$tmp/respawn-2.yaml" ||
  { diff "$tmp/batch/metrics.yaml" "$tmp/respawn-2.yaml" || true; fail "respawn: job 2 differs from the batch run"; }
echo "respawn: galvo_servo killed between jobs and respawned; job 2 complete and identical to batch" \
  "($(elapsed "$t0") s from load to metrics)"
kill -INT $graph_pid
wait_exit 30 $graph_pid || fail "the graph did not stop on SIGINT"
fi
# ---- 5. an expected consumer that never comes --------------------------------------------------
if want 5; then
  if ! rostopic list > /dev/null 2>&1; then
    roscore -p "${ROS_MASTER_URI##*:}" > "$tmp/roscore5.log" 2>&1 &
    started $!
    wait_for 30 rostopic list || fail "no ROS master"
  fi
  rosparam set /nc_interpolator/setpoint_consumers "galvo_servo optical_chain ghost_stage"
  rosparam set /nc_interpolator/ready_timeout_s 2.0
  rosparam set /energy_accumulator/start_timeout_s 5.0
  t0=$(now)
  timeout 60 roslaunch "$launch_dir/virtual_machine.launch" job:="$job" out:="$tmp/ghost" > "$tmp/ghost.log" 2>&1 ||
    { cat "$tmp/ghost.log"; fail "missing consumer: the launch did not end within 60 s"; }
  took=$(elapsed "$t0")
  rosparam delete /nc_interpolator
  rosparam delete /energy_accumulator/start_timeout_s
  grep -q "nc: job 1 abandoned: .*/ghost_stage (not connected" "$tmp/ghost.log" ||
    { cat "$tmp/ghost.log"; fail "missing consumer: the NC did not name it"; }
  grep -q "energy: job 1: no results" "$tmp/ghost.log" || { cat "$tmp/ghost.log"; fail "missing consumer: the energy node did not fail the job"; }
  [ ! -e "$tmp/ghost" ] || fail "missing consumer: a results folder was written"
  echo "missing consumer: the NC named it after 2 s, the launch ended after $took s with no results folder:" \
    "$(grep -o "nc: job 1 abandoned: .*" "$tmp/ghost.log" | sed 's/\x1b\[0m//')"
fi
# ---- 6. a slow stage downstream: alive, so no stall -------------------------------------------
stopped_pid=""  # a process this script stopped (SIGSTOP): continued on exit
trap '[ -z "$stopped_pid" ] || kill -CONT "$stopped_pid" 2> /dev/null || true; cleanup' EXIT
pause_mid_job() {  # node seconds log dir extra-args...: SIGSTOP the node mid-job for that long (0: until the energy node stalls)
  local node=$1 pause=$2 log=$3 dir=$4
  shift 4
  roslaunch "$launch_dir/virtual_machine.launch" job:="$job_long" out:="$dir" nodelets:=false "$@" > "$log" 2>&1 &
  local launch_pid=$!
  started $launch_pid
  wait_for 90 acked || { cat "$log"; fail "pause $node: the job never started"; }
  stopped_pid=$(node_pid "$node")
  [ -n "$stopped_pid" ] || fail "pause $node: no pid"
  kill -STOP "$stopped_pid"
  t0=$(now)
  if [ "$pause" = 0 ]; then
    wait_for 60 grep -q "energy: job 1 stalled" "$log" || { kill -CONT "$stopped_pid"; cat "$log"; fail "pause $node: no stall"; }
  else
    sleep "$pause"
  fi
  stop_took=$(elapsed "$t0")
  kill -CONT "$stopped_pid"
  stopped_pid=""
  wait_exit 120 $launch_pid || { cat "$log"; fail "pause $node: the launch did not end"; }
  took=$(elapsed "$t0")
}
if want 6; then
  "$run" --job "$job_long" --out "$tmp/batch_long" --quiet
  pause_mid_job /energy_accumulator 12 "$tmp/slow.log" "$tmp/slow"
  grep -q "job 1 stalled\|job 1 abandoned" "$tmp/slow.log" && { cat "$tmp/slow.log"; fail "slow stage: a live graph was declared stalled"; }
  grep -q "alive but silent for .*a slower stage downstream holds the flow" "$tmp/slow.log" ||
    { cat "$tmp/slow.log"; fail "slow stage: no warning that a stage waited on a live upstream"; }
  grep -q "nc: job 1: no energy/ack .*a slow stage holds the flow" "$tmp/slow.log" ||
    { cat "$tmp/slow.log"; fail "slow stage: the NC did not warn about its full window"; }
  [ -f "$tmp/slow/metrics.yaml" ] || { cat "$tmp/slow.log"; fail "slow stage: no results folder"; }
  cmp "$tmp/batch_long/metrics.yaml" "$tmp/slow/metrics.yaml" ||
    { diff "$tmp/batch_long/metrics.yaml" "$tmp/slow/metrics.yaml" || true; fail "slow stage: metrics differ from the batch run"; }
  echo "slow stage: energy_accumulator stopped 12 s mid-job; $(grep -c "alive but silent" "$tmp/slow.log") stage" \
    "warning(s), the NC's full-window warning, no stall; the job completed identical to batch" \
    "(launch ended $took s after the stop)"
fi

# ---- 7. a live stage that hangs: bounded by hang_timeout_s -------------------------------------
if want 7; then
  pause_mid_job /galvo_servo 0 "$tmp/hang.log" "$tmp/hang" hang_timeout_s:=5
  grep -q "energy: job 1 stalled: .*hung: .*/galvo_servo not answering but silent for more than ~hang_timeout_s" \
    "$tmp/hang.log" || { cat "$tmp/hang.log"; fail "hang: the stall does not name the hung /galvo_servo"; }
  grep -q "^complete: false$" "$tmp/hang/metrics.yaml" || fail "hang: metrics.yaml does not say complete: false"
  grep -q "exit code 1, cmd [^ ]*/energy_accumulator " "$tmp/hang.log" || { cat "$tmp/hang.log"; fail "hang: the energy node did not exit 1"; }
  awk -v t="$stop_took" 'BEGIN { exit !(t >= 5 && t < 15) }' || fail "hang: stalled $stop_took s after the stop (hang_timeout_s 5)"
  echo "hung stage: galvo_servo stopped mid-job, hang_timeout_s 5: the energy node stalled $stop_took s after" \
    "the stop naming it; launch ended $took s after the stop; $(grep -o "hung: [^;]*" "$tmp/hang.log" | head -1)"
fi
echo "graph faults: all cases passed"

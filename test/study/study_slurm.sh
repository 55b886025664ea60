#!/bin/bash
# Issue 16: a study through a real one-node Slurm cluster started here (munged, slurmctld, slurmd from Debian, a
# generated slurm.conf with its own ports and folders), checked case by case against the local backend: every
# results file byte-identical (but the run's own peak memory). Every daemon started here is stopped by PID at the end.
# Skips (exit 77, ctest: Skipped, with the reason) only where the daemons cannot start.
# usage: study_slurm.sh BIN_DIR (scanhead_study and scanhead_run)
set -euo pipefail
BIN=$(cd "$1" && pwd)
STUDY="$BIN/scanhead_study"
TMP=$(mktemp -d /tmp/scanhead_slurm.XXXXXX)
chmod 755 "$TMP"  # munged runs as the munge user and must reach its folder
PIDS=()
cleanup() {
  for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${PIDS[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  rm -rf "$TMP"
}
trap cleanup EXIT
skip() { echo "SKIPPED: $*"; exit 77; }
fail() { echo "FAIL: $*"; exit 1; }
. "$(dirname "$0")/study_test_lib.sh"

for tool in munged slurmctld slurmd sbatch squeue sinfo; do
  command -v "$tool" > /dev/null || skip "$tool is not installed (scripts/install_deps.sh installs slurmd slurmctld slurm-client munge)"
done
id munge > /dev/null 2>&1 || skip "no munge user (the munge package creates it)"
[ -r /etc/munge/munge.key ] || skip "no /etc/munge/munge.key (the munge package creates it)"

# Free ports on loopback for slurmctld and slurmd.
ports=$(/usr/bin/python3 -c 'import socket
s=[socket.socket() for _ in range(2)]
[x.bind(("127.0.0.1",0)) for x in s]
print(" ".join(str(x.getsockname()[1]) for x in s))')
read -r CTLD_PORT SLURMD_PORT <<< "$ports"

# munged: as the munge user, its own socket, pid, log and seed files.
mkdir -p "$TMP/munge"
chown munge:munge "$TMP/munge"
chmod 700 "$TMP/munge"
SOCKET="$TMP/munge/munge.socket"
runuser -u munge -- munged --force --foreground --socket="$SOCKET" --pid-file="$TMP/munge/munged.pid" \
  --log-file="$TMP/munge/munged.log" --seed-file="$TMP/munge/munged.seed" > "$TMP/munged.out" 2>&1 &
PIDS+=($!)
for _ in $(seq 50); do [ -S "$SOCKET" ] && break; sleep 0.1; done
[ -S "$SOCKET" ] || skip "munged did not start: $(cat "$TMP/munged.out" "$TMP/munge/munged.log" 2>/dev/null | tail -3)"

NODE=$(hostname -s)
CPUS=$(nproc)
mkdir -p "$TMP/state" "$TMP/spool"
export SLURM_CONF="$TMP/slurm.conf"
cat > "$SLURM_CONF" << CONF
ClusterName=scanhead_test
SlurmctldHost=$NODE(127.0.0.1)
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
AuthType=auth/munge
AuthInfo=socket=$SOCKET
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$TMP/state
SlurmdSpoolDir=$TMP/spool
SlurmctldPidFile=$TMP/slurmctld.pid
SlurmdPidFile=$TMP/slurmd.pid
SlurmctldLogFile=$TMP/slurmctld.log
SlurmdLogFile=$TMP/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$CPUS State=UNKNOWN
PartitionName=scanhead Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -D -i -f "$SLURM_CONF" > "$TMP/slurmctld.out" 2>&1 &
PIDS+=($!)
slurmd -D -f "$SLURM_CONF" > "$TMP/slurmd.out" 2>&1 &
PIDS+=($!)
state=""
for _ in $(seq 100); do
  state=$(sinfo -h -o %t 2>/dev/null || true)
  [ "$state" = "idle" ] && break
  sleep 0.2
done
[ "$state" = "idle" ] || skip "the Slurm node did not come up (state '$state'): $(tail -3 "$TMP/slurmctld.log" "$TMP/slurmd.log" 2>/dev/null)"
echo "slurm: node $NODE idle (slurmctld port $CTLD_PORT, slurmd port $SLURMD_PORT)"

# The study: a 2-layer segment file (z changes) × a 2-value grid = 4 cases.
cp "$STUDY_TEST_JOB" "$TMP/layers.txt"
cat > "$TMP/study.yaml" << 'YAML'
jobs:
  - layers.txt
set:
  cam.units: mm
  cam.centre: true
grid:
  servo.position_controller: [pd, hinf]
YAML
"$STUDY" run "$TMP/study.yaml" --out "$TMP/local" --workers 2 > "$TMP/local.out" 2>&1 || fail "local backend: $(cat "$TMP/local.out")"
"$STUDY" run "$TMP/study.yaml" --out "$TMP/slurm" --backend slurm --dry-run > "$TMP/dry.sh"
grep -q "^#SBATCH --array=0-3$" "$TMP/dry.sh" || fail "dry run: no array line 0-3: $(cat "$TMP/dry.sh")"
start=$(date +%s.%N)
"$STUDY" run "$TMP/study.yaml" --out "$TMP/slurm" --backend slurm --wait --cpus-per-task 1 > "$TMP/slurm.out" 2>&1 \
  || fail "slurm backend: $(cat "$TMP/slurm.out"; tail -5 "$TMP/slurmctld.log")"
echo "slurm: 4 cases in $(echo "$(date +%s.%N) - $start" | bc) s (submit, run, collect)"
cat "$TMP/slurm.out"
"$STUDY" status "$TMP/slurm" | grep -q "4 cases: 4 done, 0 failed, 0 pending" || fail "status: $("$STUDY" status "$TMP/slurm")"
[ -s "$TMP/slurm/summary.csv" ] || fail "the collection job wrote no summary.csv"
[ "$(wc -l < "$TMP/slurm/summary.csv")" -eq 5 ] || fail "summary.csv: $(cat "$TMP/slurm/summary.csv")"
for dir in "$TMP"/local/cases/*/; do
  id=$(basename "$dir")
  [ -d "$TMP/slurm/cases/$id" ] || fail "case $id is missing from the Slurm run"
  same_results "${dir%/}" "$TMP/slurm/cases/$id"
done
[ "$COMPARED" -ge 40 ] || fail "only $COMPARED files compared"
echo "PASS: 4 cases through Slurm, $COMPARED files byte-identical to the local backend's"

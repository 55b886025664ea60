#!/bin/bash
# Issue 16: scanhead_study with the local backend, as a user runs it.
#  - bad study files: an unknown key, a glob that matches nothing, a grid key the config does not have, a value no
#    case can run with: clear errors naming the study file and the key, nothing run;
#  - a 2-layer segment file (z changes) × a 2-value grid = 4 cases, plus a job that fails: the failure is kept with
#    its error (status, summary) and does not stop the others; --retry-failed runs it again;
#  - each case folder is what scanhead_run writes for the same job and settings, byte for byte;
#  - a study killed with SIGKILL mid-way (its whole process group) loses no finished case: the re-run skips them
#    (their files untouched) and runs only the rest.
# usage: study_local.sh BIN_DIR (scanhead_study and scanhead_run)
set -euo pipefail
BIN=$(cd "$1" && pwd)
STUDY="$BIN/scanhead_study"
RUN="$BIN/scanhead_run"
TMP=$(mktemp -d /tmp/scanhead_study.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
. "$(dirname "$0")/study_test_lib.sh"
expect_error() {  # expect_error TEXT ARGS...: the command fails, naming TEXT
  local text=$1
  shift
  if "$@" > "$TMP/err.out" 2>&1; then fail "no error for: $*"; fi
  grep -qF -- "$text" "$TMP/err.out" || fail "expected '$text' in: $(cat "$TMP/err.out")"
}
cd "$TMP"

# The 2-layer Peregrine-style file of study_test_lib.sh and a bad one.
cp "$STUDY_TEST_JOB" layers.txt
printf 'Mode\tX(mm)\tY(mm)\tZ(mm)\tPmod\ttParam\n1\t0\t0\t0\t0\t0\n0\t1\t0\t0\t1\t-0.8\n' > broken.txt

# Bad study files.
printf 'jobs: [layers.txt]\njbos: 1\n' > bad_key.yaml
expect_error "bad_key.yaml:2: unknown key 'jbos'" "$STUDY" run bad_key.yaml --out bad
printf 'jobs:\n  - nothing_*.cli\n' > bad_glob.yaml
expect_error "bad_glob.yaml:2: jobs[0]: 'nothing_*.cli' matches no file" "$STUDY" run bad_glob.yaml --out bad
printf 'jobs: [corner]\ngrid:\n  servo.no_such_key: [1, 2]\n' > bad_grid.yaml
expect_error "bad_grid.yaml:3: grid.servo.no_such_key: not a setting of the config" "$STUDY" run bad_grid.yaml --out bad
printf 'jobs: [corner]\ngrid:\n  nc.fir_t1_s: [1e-4, -1]\n' > bad_value.yaml
expect_error "bad_value.yaml: settings (grid: nc.fir_t1_s=-1)" "$STUDY" run bad_value.yaml --out bad
expect_error "not a study folder" "$STUDY" status "$TMP/nowhere"
[ ! -e bad ] || fail "a bad study file left a folder"

cat > study.yaml << 'YAML'
jobs: [layers.txt, broken.txt]
set: {cam.units: mm, cam.centre: true}
grid: {servo.position_controller: [pd, hinf]}
YAML
# 2 layers × 2 + the broken file × 2 = 6 cases, 2 of which fail.
if "$STUDY" run study.yaml --out out --workers 2 > run1.out 2>&1; then fail "a study with failed cases exited 0"; fi
grep -q "6 cases: 0 done, 0 failed, 6 to run (local, 2 at once)" run1.out || fail "plan line: $(cat run1.out)"
grep -q "6 cases to run: .* of machine time, estimated .* here (the chains; run plans), 2 cases unreadable" run1.out \
  || fail "no time estimate before the run: $(cat run1.out)"
"$STUDY" status out > status.out
grep -q "6 cases: 4 done, 2 failed, 0 pending" status.out || fail "status: $(cat status.out)"
grep -q "failed broken_position_controller-pd_.*param: a line's speed must be > 0 m/s" status.out \
  || fail "the failure's error is not kept: $(cat status.out)"
[ "$(ls out/cases | wc -l)" -eq 4 ] || fail "expected 4 case folders: $(ls out/cases)"
grep -q "^layers_layer0001_position_controller-hinf_[0-9a-f]*,layers.txt,1,hinf,done," out/summary.csv \
  || fail "summary.csv: $(cut -c1-120 out/summary.csv)"
grep -q "broken_position_controller-pd.*,failed," out/summary.csv || fail "summary.csv has no failed row"
grep -q "## Failed cases" out/summary.md || fail "summary.md names no failure"
[ -s out/summary_layers.png ] && [ -s out/summary_grid.png ] || fail "no study plots: $(ls out)"

# A case folder = scanhead_run's for the same job and settings (but the process's peak memory).
case_dir=$(ls -d out/cases/layers_layer0000_position_controller-pd_*)
"$RUN" --job layers.txt --set cam.units=mm --set cam.centre=true --set servo.position_controller=pd \
  --set cam.layer=0 --out direct --plots none --quiet > /dev/null
same_results direct "$case_dir"
[ "$COMPARED" -ge 9 ] || fail "only $COMPARED files compared with scanhead_run's"
grep -q "placement: {rotation_deg: 0, offset_m: \[-0.19925" "$case_dir/metrics.yaml" \
  || fail "the whole file's centre is not the placement: $(grep placement "$case_dir/metrics.yaml")"

# Threads: with 2 workers a case started while others wait runs on one thread, the last on stream.threads (2).
printf 'jobs: [corner]\ngrid: {nc.fir_t1_s: [2.0e-4, 2.6e-4, 3.0e-4]}\n' > threads.yaml
"$STUDY" run threads.yaml --out threads --workers 2 > threads.out 2>&1 || fail "threads study: $(cat threads.out)"
[ "$(grep -l "^  threads: 1$" threads/cases/*/config.yaml | wc -l)" -eq 2 ] \
  && grep -q "^  threads: 2$" threads/cases/*fir_t1_s-3.0e-4*/config.yaml \
  || fail "thread counts: $(grep -H "^  threads:" threads/cases/*/config.yaml)"

# Re-run: finished cases skipped, failures kept unless --retry-failed.
if "$STUDY" run study.yaml --out out > run2.out 2>&1; then fail "exit 0 with failed cases"; fi
grep -q "6 cases: 4 done, 2 failed (kept; --retry-failed runs them again), 0 to run" run2.out || fail "$(cat run2.out)"
if "$STUDY" run study.yaml --out out --retry-failed > run3.out 2>&1; then fail "exit 0 with failed cases"; fi
grep -q "2 to run" run3.out || fail "--retry-failed: $(cat run3.out)"

# SIGKILL mid-way: a study of 6 longer cases, killed with its children once 2 are done.
cat > slow.yaml << 'YAML'
jobs:
  - hatch:size=0.004,spacing=0.0001
grid:
  nc.fir_t1_s: [2.0e-4, 2.2e-4, 2.4e-4]
  energy.pixel_m: [5.0e-6, 6.0e-6]
YAML
setsid "$STUDY" run slow.yaml --out slow --workers 1 > slow1.out 2>&1 &
pid=$!
for _ in $(seq 600); do
  [ "$(ls slow/cases 2>/dev/null | wc -l)" -ge 2 ] && break
  sleep 0.05
done
kill -9 -- -"$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
finished=$(ls slow/cases | wc -l)
[ "$finished" -ge 2 ] && [ "$finished" -lt 6 ] || fail "killed after $finished of 6 cases"
kept=$(ls slow/cases)
before=$(cd slow/cases && find $kept -type f -printf '%p %T@ %s\n' | sort | md5sum)
"$STUDY" run slow.yaml --out slow > slow2.out 2>&1 || fail "resume: $(cat slow2.out)"
grep -q "6 cases: $finished done, 0 failed, $((6 - finished)) to run" slow2.out || fail "resume plan: $(cat slow2.out)"
"$STUDY" status slow | grep -q "6 cases: 6 done" || fail "not all done after the resume"
after=$(cd slow/cases && find $kept -type f -printf '%p %T@ %s\n' | sort | md5sum)
[ "$before" = "$after" ] || fail "the resume touched finished cases"
# A worker killed from outside (the OOM killer, a user): that case fails with the signal, the others go on.
rm -rf slow
"$STUDY" run slow.yaml --out slow --workers 2 > kill1.out 2>&1 &
pid=$!
victim=""
for _ in $(seq 600); do
  victim=$(pgrep -f "scanhead_run --job hatch:size=0.004.*--out slow/cases/" | head -1 || true)
  [ -n "$victim" ] && break
  sleep 0.02
done
[ -n "$victim" ] || fail "no case process to kill"
kill -9 "$victim"
if wait "$pid"; then fail "exit 0 after a killed case"; fi
"$STUDY" status slow > kill_status.out
grep -q "6 cases: 5 done, 1 failed, 0 pending" kill_status.out || fail "after a killed worker: $(cat kill_status.out)"
grep -q "killed by signal 9" kill_status.out || fail "the failure does not name the signal: $(cat kill_status.out)"

echo "PASS: bad files refused, 6 cases with 2 failures kept, a case = scanhead_run's, SIGKILL after $finished: resumed"

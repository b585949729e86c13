#!/usr/bin/env bash
# `rovo batch` on a real Slurm (Debian's slurm-wlm and munge): starts munged, slurmctld and slurmd on
# localhost with a generated slurm.conf, runs a tiny suite through Slurm and locally and compares the
# results byte for byte (apart from times, CPU and memory), then cancels a task of a second batch and checks
# that `rovo batch status` reports it and `rovo batch resume` completes the batch without redoing
# finished work. Usage: slurm_batch_test.sh /path/to/rovo. Stops its daemons on any exit.
set -euo pipefail

ROVO=$(readlink -f "${1:?usage: slurm_batch_test.sh ROVO_BINARY}")
for tool in munged mungekey slurmctld slurmd sbatch squeue scancel scontrol; do
  command -v "$tool" >/dev/null || { echo "FAIL: $tool not found (ci/install-deps.sh installs slurm-wlm and munge)"; exit 1; }
done

T=$(mktemp -d /tmp/rovo-slurm-test.XXXXXX)
chmod 755 "$T"
DAEMONS=()
cleanup() {
  local rc=$?
  set +e
  if [ -n "${SLURM_CONF:-}" ] && [ -f "$SLURM_CONF" ]; then
    scancel --quiet --user="$(id -un)" 2>/dev/null
    for _ in $(seq 1 20); do [ -z "$(squeue -h 2>/dev/null)" ] && break; sleep 1; done
  fi
  for ((i = ${#DAEMONS[@]} - 1; i >= 0; i--)); do kill "${DAEMONS[i]}" 2>/dev/null; done
  for pid in "${DAEMONS[@]}"; do
    for _ in $(seq 1 20); do kill -0 "$pid" 2>/dev/null || break; sleep 0.5; done
    kill -9 "$pid" 2>/dev/null
  done
  if [ "$rc" -ne 0 ]; then
    echo "---- test failed (exit $rc); daemon and task logs:"
    for f in "$T"/slurmctld.log "$T"/slurmd.log "$T"/munge/munged.log; do
      [ -f "$f" ] && { echo "== $f"; tail -n 30 "$f"; }
    done
    for f in "$T"/suite/batch/logs/* "$T"/suite2/batch/logs/*; do
      [ -f "$f" ] && { echo "== $f"; tail -n 15 "$f"; }
    done
  fi
  rm -rf "$T"
  exit "$rc"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }
step() { echo "[$(date +%T)] $*"; }

# ---- munge with its own key and socket.
mkdir -p "$T/munge" "$T/state" "$T/spool"
chmod 700 "$T/munge"
mungekey --create --keyfile="$T/munge/munge.key" --force
munged -F --force --socket="$T/munge/munge.sock" --key-file="$T/munge/munge.key" --pid-file="$T/munge/munged.pid" \
  --log-file="$T/munge/munged.log" --seed-file="$T/munge/munged.seed" > /dev/null 2>&1 &
DAEMONS+=($!)
for _ in $(seq 1 50); do [ -S "$T/munge/munge.sock" ] && break; sleep 0.1; done
[ -S "$T/munge/munge.sock" ] || fail "munged did not start"

# ---- slurm.conf: one node with this machine's CPUs and memory, everything under $T.
HOST=$(hostname -s)
CPUS=$(nproc)
MEM_MB=$(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo)
PORT=$((20000 + $$ % 20000))
export SLURM_CONF="$T/slurm.conf"
cat > "$SLURM_CONF" <<EOF
ClusterName=rovotest
SlurmctldHost=$HOST(127.0.0.1)
SlurmctldPort=$PORT
SlurmdPort=$((PORT + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$T/munge/munge.sock
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
MinJobAge=30
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM_MB State=UNKNOWN
PartitionName=rovo Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
step "starting slurmctld and slurmd ($CPUS CPUs, $MEM_MB MB, ports $PORT-$((PORT + 1)))"
slurmctld -D -i > /dev/null 2>&1 &
DAEMONS+=($!)
slurmd -D -N "$HOST" > /dev/null 2>&1 &
DAEMONS+=($!)
for _ in $(seq 1 60); do
  state=$(sinfo -h -N -o '%T' 2>/dev/null | head -n 1 || true)
  [ "$state" = idle ] && break
  sleep 1
done
[ "$state" = idle ] || fail "the node did not become idle (state '$state')"

wait_queue_empty() {  # $1: seconds
  for _ in $(seq 1 "$1"); do
    [ -z "$(squeue -h)" ] && return 0
    sleep 1
  done
  squeue
  fail "jobs still queued after $1 s"
}

# suite.json and table.md without what differs between any two runs: the timing fields (mean_time_ms,
# its statistic) and the cost per system (wall and CPU time, memory).
COST_KEYS='"cost_per_run", "wall_s", "cpu_s", "user_cpu_s", "system_cpu_s", "process_maxrss_mb", "peak_rss_mb", "cpu_overlapped"'
strip_timing() {
  python3 -c '
import json, sys
COST = {'"$COST_KEYS"'}
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if "time" not in k and k not in COST}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
print(json.dumps(strip(json.load(open(sys.argv[1]))), indent=1, sort_keys=True))' "$1"
}

SUITE_ARGS=(--presets cloudy_urban --quick --frames 16 --seeds 1 --draws 1 --vo-threads 1 --no-plots)
RESOURCES=(--shards 2 --render-cpus 1 --render-mem 1G --vo-cpus 1 --vo-mem 1G --merge-cpus 1 --merge-mem 1G)

# ---- 1. The local suite, moved aside so that the Slurm run writes to the same paths.
step "local suite"
"$ROVO" suite "${SUITE_ARGS[@]}" --out "$T/suite" --jobs 2 > "$T/local.out" 2>&1 || { cat "$T/local.out"; fail "local suite"; }
mv "$T/suite" "$T/local"

# ---- 2. The same suite through Slurm.
step "batch plan + submit"
"$ROVO" batch plan "${SUITE_ARGS[@]}" "${RESOURCES[@]}" --out "$T/suite"
for f in render.sbatch vo.sbatch merge.sbatch submit.sh plan.json; do
  [ -f "$T/suite/batch/$f" ] || fail "batch folder lacks $f"
done
grep -q -- '--array=0-3' "$T/suite/batch/vo.sbatch" || fail "vo.sbatch: expected 4 VO tasks (gt, noisy_0, online_0, draw_0)"
"$ROVO" batch submit --dry-run "$T/suite/batch" > "$T/dry.out"
grep -q 'dependency=afterok:<vo job id>' "$T/dry.out" || { cat "$T/dry.out"; fail "dry run: merge does not wait for vo"; }
[ ! -f "$T/suite/batch/jobs.tsv" ] || fail "--dry-run submitted jobs"
"$ROVO" batch submit "$T/suite/batch"
wait_queue_empty 600
"$ROVO" batch status "$T/suite/batch" | tee "$T/status1.out"
grep -q 'Done: 7 of 7 tasks' "$T/status1.out" || fail "batch 1 did not finish every task"

step "comparing the Slurm run with the local run"
diff <(strip_timing "$T/local/suite.json") <(strip_timing "$T/suite/suite.json") || fail "suite.json differs"
strip_cost_md() { awk '/^## Cost per system/ {skip = 1; next} /^## / {skip = 0} !skip' "$1"; }
diff <(strip_cost_md "$T/local/table.md") <(strip_cost_md "$T/suite/table.md") || fail "table.md differs"
grep -q 'OnlineExt from fresh perturbation draws' "$T/suite/table.md" || fail "table.md lacks the draws table"
diff -r "$T/local/data" "$T/suite/data" || fail "the sharded render differs from the local render"
for run in gt noisy_0 online_0 draw_0; do
  for f in trajectory.tum extrinsics.csv; do
    cmp "$T/local/runs/cloudy_urban/$run/$f" "$T/suite/runs/cloudy_urban/$run/$f" || fail "runs/$run/$f differs"
  done
done
[ "$(ls "$T/suite/batch/logs" | wc -l)" -eq 7 ] || fail "expected 7 task logs"

# ---- 3. A second batch (other VO seed, same datasets): cancel a VO task, check status, resume.
step "batch 2: cancel a task, status, resume"
"$ROVO" batch plan "${SUITE_ARGS[@]}" "${RESOURCES[@]}" --vo-seed 1 --data "$T/suite/data" --out "$T/suite2"
B2="$T/suite2/batch"
scontrol update PartitionName=rovo State=DOWN  # hold every job until the task is cancelled
"$ROVO" batch submit "$B2"
vo_job=$(awk -F'\t' '$1 == "vo" {print $2}' "$B2/jobs.tsv")
scancel "${vo_job}_2"
scontrol update PartitionName=rovo State=UP
wait_queue_empty 600
"$ROVO" batch status "$B2" | tee "$T/status2.out"
grep -q "vo\[2\] lost" "$T/status2.out" || fail "status does not report the cancelled task vo[2]"
grep -q "merge\[0\] lost" "$T/status2.out" || fail "status does not report the merge that never ran"
grep -q "render  2 tasks: 2 done" "$T/status2.out" || fail "render tasks not done"
[ ! -f "$T/suite2/suite.json" ] || fail "the merge ran although a VO task was cancelled"
before=$(stat -c '%n %Y' "$T"/suite2/runs/cloudy_urban/{gt,noisy_0,draw_0}/run.json "$B2"/state/*.done)

"$ROVO" batch resume "$B2" | tee "$T/resume.out"
grep -q '^vo: job [0-9]*, array 2$' "$T/resume.out" || fail "resume did not resubmit exactly vo[2]"
grep -q '^merge: job' "$T/resume.out" || fail "resume did not resubmit the merge"
grep -q '^render' "$T/resume.out" && fail "resume resubmitted rendering"
wait_queue_empty 600
"$ROVO" batch status "$B2" | tee "$T/status3.out"
grep -q 'Done: 7 of 7 tasks' "$T/status3.out" || fail "the resumed batch did not finish"
after=$(stat -c '%n %Y' "$T"/suite2/runs/cloudy_urban/{gt,noisy_0,draw_0}/run.json $(echo "$before" | awk '{print $1}' | grep state/))
[ "$before" = "$after" ] || fail "resume redid finished work: $(diff <(echo "$before") <(echo "$after"))"
[ -f "$T/suite2/suite.json" ] && [ -f "$T/suite2/runs/cloudy_urban/online_0/run.json" ] || fail "resumed outputs missing"
"$ROVO" batch resume "$B2" | grep -q 'every task is done' || fail "a second resume should have nothing to do"
step "PASS"

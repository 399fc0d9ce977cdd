#!/usr/bin/env bash
# End-to-end check of the Slurm job-array path on a real single-node Slurm started here:
# munged, slurmctld and slurmd (Debian's slurm-wlm + munge) with a minimal slurm.conf in a
# temporary folder, run as root. It submits a small sweep as a 3-shard job array, breaks one
# shard and checks merge names it, resubmits that shard (it resumes), merges, and compares the
# merged table, report and figures byte for byte with an unsharded local run. The daemons
# are stopped and the folder removed on exit, also when interrupted.
#
#   scripts/slurm/test_slurm.sh RECRUIT_BINARY [SOURCE_DIR]
#
# Exit 0 pass, 1 fail, 77 skipped (no slurmctld/munged, or not root): ctest's SKIP_RETURN_CODE.
set -euo pipefail
recruit=$(realpath "$1")
src=$(realpath "${2:-$(dirname "$0")/../..}")
here="$src/scripts/slurm"
for prog in slurmctld slurmd munged sbatch squeue; do
  if ! command -v "$prog" > /dev/null 2>&1 && [ ! -x "/usr/sbin/$prog" ]; then
    echo "SKIP: $prog is not installed (apt-get install slurm-wlm munge)"
    exit 77
  fi
done
if [ "$(id -u)" != 0 ]; then
  echo "SKIP: starting slurmd needs root"
  exit 77
fi
export PATH="$PATH:/usr/sbin"

tmp=$(mktemp -d /tmp/recruit_slurm.XXXXXX)
chmod 755 "$tmp"
pids=()
cleanup() {
  set +e
  if [ -n "${SLURM_CONF:-}" ] && [ -e "$SLURM_CONF" ]; then
    scancel --quiet --full "--name=recruit-sweep" 2> /dev/null
    scancel --quiet --full "--name=recruit-merge" 2> /dev/null
    for _ in $(seq 20); do  # jobs end before their slurmd goes
      [ -z "$(squeue -h 2> /dev/null)" ] && break
      sleep 0.5
    done
  fi
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill "${pids[$i]}" 2> /dev/null; done
  for p in "${pids[@]}"; do
    for _ in $(seq 20); do kill -0 "$p" 2> /dev/null || break; sleep 0.25; done
    kill -9 "$p" 2> /dev/null
  done
  if [ -f "$tmp/munged.pid" ]; then  # munged writes its seed file as it exits: wait for it
    m=$(cat "$tmp/munged.pid")
    kill "$m" 2> /dev/null
    for _ in $(seq 20); do kill -0 "$m" 2> /dev/null || break; sleep 0.25; done
  fi
  if [ "${keep:-0}" = 1 ]; then echo "kept $tmp"; else rm -rf "$tmp"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM
fail() {
  echo "FAIL: $*"
  for f in "$tmp"/slurmctld.log "$tmp"/slurmd.log "$tmp"/out/*.log; do
    [ -f "$f" ] && { echo "--- $f"; tail -n 15 "$f"; }
  done
  exit 1
}

# munge with its own key and socket (the system's munged, if any, is left alone).
dd if=/dev/urandom of="$tmp/munge.key" bs=1024 count=1 status=none
chmod 600 "$tmp/munge.key"
mkdir -m 700 "$tmp/munge"
munged --force --key-file="$tmp/munge.key" --socket="$tmp/munge/munge.sock" \
  --pid-file="$tmp/munged.pid" --log-file="$tmp/munged.log" --seed-file="$tmp/munge.seed" \
  || fail "munged did not start"

# Two free ports for slurmctld and slurmd.
read -r port1 port2 < <(python3 -c 'import socket
s=[socket.socket() for _ in range(2)]
[x.bind(("127.0.0.1",0)) for x in s]
print(*[x.getsockname()[1] for x in s])')
node=$(hostname -s)
mkdir -p "$tmp/state" "$tmp/spool" "$tmp/out"
cat > "$tmp/slurm.conf" << CONF
ClusterName=recruittest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port1
SlurmdPort=$port2
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/munge.sock
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
SlurmdTimeout=30
InactiveLimit=0
KillWait=2
MinJobAge=30
NodeName=$node NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$tmp/slurm.conf"
slurmctld -D -i -f "$SLURM_CONF" > "$tmp/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N "$node" -f "$SLURM_CONF" > "$tmp/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 60); do
  state=$(sinfo -h -N -o '%T' 2> /dev/null | head -n 1 || true)
  [ "$state" = idle ] && break
  sleep 0.5
done
[ "$state" = idle ] || fail "the node did not come up (state '$state')"
echo "slurm up: node $node idle, ports $port1/$port2"

# The sweep: dT x N x load-cell noise (2 x 2 x 2, 1 seed, 6 s) on the isometric bench.
cat > "$tmp/sweep.json" << JSON
{"task": "$src/models/tasks/isometric_steps.json", "duration": 6,
 "controller": {"dT": [0.5, 1], "estimator": "output", "seeds": 1},
 "plant": {"axes": [
   {"name": "N", "path": "model:bundle_units/units", "values": [30, 90], "integer": true},
   {"name": "noise_std", "path": "/sensor/noise_std", "values": [0.01, 0.2]}]}}
JSON
args=(--sweep "$tmp/sweep.json")
"$recruit" sweep "${args[@]}" --out "$tmp/local" --threads 1 > /dev/null \
  || fail "the local unsharded sweep failed"

out="$tmp/out"
wait_job() {  # sbatch --wait without holding a terminal: poll until the job leaves the queue
  for _ in $(seq 120); do
    [ -z "$(squeue -h -j "$1" 2> /dev/null)" ] && return 0
    sleep 0.5
  done
  fail "job $1 did not finish in 60 s"
}
compare() {
  for f in table.csv table.md report.md report.html margin.png critical_dt.svg; do
    cmp "$tmp/local/$f" "$out/merged/$f" || fail "$f differs between the Slurm shards and the local run"
  done
}

# submit.sh: the 3-task array and the merge job that waits for it (afterany).
ids=$(RECRUIT="$recruit" "$here/submit.sh" 3 "$out" "${args[@]}") || fail "submit.sh failed: $ids"
ids=${ids%%$'\n'*}
echo "$ids"
array=$(sed -n 's/^array job \([0-9]*\) .*/\1/p' <<< "$ids")
merge=$(sed -n 's/.*merge job \([0-9]*\);.*/\1/p' <<< "$ids")
[ -n "$array" ] && [ -n "$merge" ] || fail "submit.sh printed no job ids: $ids"
wait_job "$array"
wait_job "$merge"
for k in 1 2 3; do
  [ -f "$out/shard_$k/shard.json" ] || fail "shard $k did not finish"
done
[ -f "$out/merged/table.csv" ] || fail "the merge job wrote no table"
compare

# A failed task: shard 2 loses a run and its manifest; merge must name it, a resubmission of just
# that task resumes (one run made), and the merge job then succeeds again.
rm -r "$out/merged" "$out/shard_2/shard.json" "$(ls "$out"/shard_2/runs/*.json | head -n 1)"
if "$recruit" sweep merge "${args[@]}" --out "$out/merged" "$out"/shard_* 2> "$tmp/merge.err"; then
  fail "merge accepted an incomplete shard"
fi
grep -q -- "--array=2 " "$tmp/merge.err" || fail "merge did not name shard 2: $(cat "$tmp/merge.err")"
job=$(sbatch --parsable --array=2 --chdir="$tmp" --output="$out/shard_%a.retry.log" \
  --export="ALL,SHARDS=3,RECRUIT=$recruit" "$here/sweep_array.sh" "$out" "${args[@]}")
wait_job "${job%%;*}"
grep -q "1 runs made" "$out/shard_2.retry.log" || fail "the resubmitted shard did not resume"
rm -r "$out/merged"
job=$(sbatch --parsable --chdir="$tmp" --output="$out/merge2.log" \
  --export="ALL,RECRUIT=$recruit" "$here/merge_job.sh" "$out" "${args[@]}")
wait_job "${job%%;*}"
compare
echo "PASS: 3 Slurm array shards of a dT x N x noise sweep (submit.sh; one failed and resubmitted)" \
  "merge to the local table, report and figures byte for byte"

#!/bin/bash
# A campaign over a real single-node Slurm cluster (about 30 s): munged, slurmctld and slurmd started
# here on localhost (a slurm.conf, a munge key and ports of their own, in a temporary folder, all
# stopped and removed at the end), examples/slurm/submit_campaign.sh runs the campaign as an array of 3
# shards and merges them, and the merged runs.csv and report.md must equal, byte for byte, those of the
# same campaign run on one machine. Needs root (the daemons run as root) and Debian's slurm-wlm and munge
# (scripts/setup.sh --test); skipped (exit 77) without them.
#   tests/slurm/test_slurm_campaign.sh TETRA SOURCE_DIR
set -euo pipefail
tetra=$1 src=$2
for program in munged slurmctld slurmd sbatch squeue sinfo; do
  command -v "$program" >/dev/null || { echo "SKIP: $program not installed (scripts/setup.sh --test)"; exit 77; }
done
[ "$(id -u)" -eq 0 ] || { echo "SKIP: the Slurm daemons of this test run as root"; exit 77; }

dir=$(mktemp -d /tmp/tetra-slurm.XXXXXX)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  rm -rf "$dir"
}
trap cleanup EXIT
cd "$dir"
mkdir state spool

# Ports of their own: a free pair in 20000-59999 (another cluster or test may hold the defaults).
port=0
for _ in $(seq 20); do
  candidate=$((20000 + RANDOM % 40000))
  if ! ss -ltnH "( sport = :$candidate or sport = :$((candidate + 1)) )" 2>/dev/null | grep -q .; then
    port=$candidate
    break
  fi
done
[ "$port" -ne 0 ] || { echo "FAIL: no free port pair"; exit 1; }

head -c 1024 /dev/urandom >munge.key
chmod 0400 munge.key
munged --socket="$dir/munge.sock" --key-file="$dir/munge.key" --pid-file="$dir/munged.pid" \
  --log-file="$dir/munged.log" --seed-file="$dir/munge.seed" --force
pids+=("$(cat munged.pid)")

cat >slurm.conf <<CONF
ClusterName=tetratest
SlurmctldHost=localhost
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.sock
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
MinJobAge=60
SlurmdParameters=config_overrides
NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=10 State=UP
CONF
export SLURM_CONF=$dir/slurm.conf
slurmctld -f "$SLURM_CONF"
for _ in $(seq 300); do [ -s slurmctld.pid ] && break; sleep 0.1; done
pids+=("$(cat slurmctld.pid)")
slurmd -f "$SLURM_CONF" -N localhost
for _ in $(seq 300); do [ -s slurmd.pid ] && break; sleep 0.1; done
[ -s slurmd.pid ] || { echo "slurmd wrote no pid file within 30 s; its log:"; cat slurmd.log 2>/dev/null; exit 1; }
pids+=("$(cat slurmd.pid)")
# Under a loaded machine (the whole suite on two cores) slurmd can take tens of seconds to register: 60 s.
for _ in $(seq 300); do
  sinfo -h -o %t 2>/dev/null | grep -qx idle && break
  sleep 0.2
done
sinfo -h -o %t | grep -qx idle || { echo "FAIL: the node never became idle"; cat slurmctld.log slurmd.log; exit 1; }

# 2 kinds x 2 gyros x 2 seeds + 2 fault-free = 10 closed-loop runs of 2 min.
cat >spec.yaml <<SPEC
scenarios: [$src/examples/sim/closed_loop_nadir.yaml]
duration_s: 120
kinds: [bias, stuck]
sizes: {bias: [0.01]}
gyros: [1, 4]
onsets_s: [60]
seeds: [1, 2]
fault_free: true
SPEC
"$tetra" campaign spec.yaml --out one --jobs 2 2>one.log

export TETRA=$tetra
submitted=$("$src/examples/slurm/submit_campaign.sh" spec.yaml "$dir/cluster" 3 --cpus-per-task=1)
echo "$submitted"
merge_job=$(sed -n 's/.*merge job \([0-9]*\).*/\1/p' <<<"$submitted")
for _ in $(seq 600); do  # 120 s: the shards and the merge, each a job of its own
  [ -z "$(squeue -h -j "$merge_job" 2>/dev/null)" ] && break
  sleep 0.2
done
[ -z "$(squeue -h -j "$merge_job" 2>/dev/null)" ] || { echo "FAIL: the merge job still queued after 120 s"; squeue; cat slurmctld.log; exit 1; }
for f in cluster/slurm-*.out; do echo "== $f"; cat "$f"; done
[ -f cluster/merged/report.md ] || { echo "FAIL: no merged report"; exit 1; }
for k in 1 2 3; do
  grep -q "^shard $k/3$" "cluster/shard-$k/shard.txt" || { echo "FAIL: shard $k/3 not run"; exit 1; }
done
cmp one/runs.csv cluster/merged/runs.csv
cmp one/report.md cluster/merged/report.md
echo "PASS: 3 Slurm array tasks merged equal the one-machine campaign ($(($(wc -l <one/runs.csv) - 1)) runs)"

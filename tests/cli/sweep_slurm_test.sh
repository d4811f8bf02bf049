#!/usr/bin/env bash
# `conform sweep --slurm --submit` against a real Slurm: the test starts a one-node cluster of
# its own (munged, slurmctld, slurmd from Debian's slurm-wlm packages, a slurm.conf in a
# temporary folder with this host as the only node, free ports), submits a 2 x 2 array through
# conform, waits for it, gathers, and compares the table with the local pool's. It stops every
# daemon it started. It needs root (slurmd runs the jobs as the submitting user and needs to
# switch users), as CI is; otherwise it is skipped (exit 77).
# Usage: bash sweep_slurm_test.sh <conform> <source dir> <build dir>
set -euo pipefail
conform="$(realpath "$1")"
fail() { echo "sweep_slurm_test: $*" >&2; exit 1; }
if [[ $(id -u) -ne 0 ]]; then echo "sweep_slurm_test: skipped, needs root"; exit 77; fi
for tool in munged slurmctld slurmd sbatch squeue scontrol sinfo; do
  command -v "$tool" > /dev/null || fail "$tool is missing (scripts/deps.sh installs slurmctld slurmd slurm-client munge)"
done
tmp="$(realpath "$(mktemp -d)")"
chmod 755 "$tmp"
export SLURM_CONF="$tmp/slurm.conf"
stop_cluster() {
  # Only the daemons this test started, by the pids they wrote.
  scontrol shutdown > /dev/null 2>&1 || true
  for pidfile in "$tmp/slurmd.pid" "$tmp/slurmctld.pid" "$tmp/munge/pid"; do
    [[ -s "$pidfile" ]] || continue
    local pid; pid="$(cat "$pidfile")"
    for _ in $(seq 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
    kill "$pid" 2> /dev/null || true
  done
}
on_exit() {
  local rc=$?
  stop_cluster
  if [[ $rc -ne 0 ]]; then
    for log in slurmctld.log slurmd.log munge/log; do
      [[ -f "$tmp/$log" ]] && { echo "--- $log" >&2; tail -20 "$tmp/$log" >&2; }
    done
  fi
  rm -rf "$tmp"
}
trap on_exit EXIT

# munge: a key of our own, a socket in the folder.
mkdir -m 700 "$tmp/munge"
head -c 1024 /dev/urandom > "$tmp/munge/key"
chmod 400 "$tmp/munge/key"
munged --force --socket="$tmp/munge/sock" --key-file="$tmp/munge/key" \
  --pid-file="$tmp/munge/pid" --log-file="$tmp/munge/log" --seed-file="$tmp/munge/seed"

# Two free TCP ports for slurmctld and slurmd.
read -r ctld_port slurmd_port < <(python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')
host="$(hostname -s)"
mkdir -p "$tmp/state" "$tmp/spool"
cat > "$SLURM_CONF" <<CONF
ClusterName=conformtest
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$tmp/munge/sock
CredType=cred/munge
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
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
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=conformnode NodeHostname=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=conformq Nodes=conformnode Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF" -N conformnode
up=0
for _ in $(seq 150); do
  if sinfo -h -o %T 2> /dev/null | grep -q idle; then up=1; break; fi
  sleep 0.2
done
[[ $up -eq 1 ]] || fail "the one-node cluster did not come up in 30 s"

# The sweep as a job array, through conform itself.
grid=(--grid arm.kp=0.3,0.5 --grid physics.substeps=1,2 --steps 20 --set outputs.frames_every=0)
# --sbatch-line passes any directive: the job carries the comment.
"$conform" sweep arm-track "${grid[@]}" --slurm --submit --partition conformq --time 00:05:00 \
  --array-limit 2 --sbatch-line=--comment=from-sbatch-line --out "$tmp/slurm" > "$tmp/submit.log" 2>&1 ||
  { cat "$tmp/submit.log" >&2; fail "submit failed"; }
job="$(sed -n 's/^submitted job \([0-9][0-9]*\)$/\1/p' "$tmp/submit.log")"
[[ -n "$job" ]] || { cat "$tmp/submit.log" >&2; fail "no job id printed"; }
[[ "$(scontrol show job "$job")" == *Comment=from-sbatch-line* ]] || fail "the --sbatch-line directive did not reach the job"
done_=0
for _ in $(seq 600); do
  if [[ -z "$(squeue -h -j "$job" 2> /dev/null)" ]]; then done_=1; break; fi
  sleep 0.2
done
[[ $done_ -eq 1 ]] || { squeue >&2; fail "job $job did not finish in 120 s"; }
# Every task wrote its Slurm log, and ran on the cluster's node.
[[ $(ls "$tmp/slurm/slurm/${job}"_*.out | wc -l) -eq 4 ]] || { ls -R "$tmp/slurm" >&2; fail "not 4 task logs"; }
"$conform" sweep --gather "$tmp/slurm" > "$tmp/gather.log" 2>&1 ||
  { cat "$tmp/gather.log" "$tmp/slurm/slurm/"*.out >&2; fail "gather after the array failed"; }
grep -q "4 of 4 points finished, 0 failed, 0 missing" "$tmp/gather.log" || fail "gather count"

# The local path on the same grid: the same table (except timings).
"$conform" sweep arm-track "${grid[@]}" --jobs 2 --out "$tmp/local" > "$tmp/local.log" 2>&1 ||
  { cat "$tmp/local.log" >&2; fail "local sweep failed"; }
python3 - "$tmp" <<'PY' || fail "the Slurm table differs from the local one"
import csv, sys
t = sys.argv[1]
def table(name):
    rows = list(csv.DictReader(open(f"{t}/{name}/sweep.csv")))
    keep = lambda k: not (k.startswith("timings.") or k == "run_wall_s" or k == "metrics.ik_ns_per_solve")
    return [{k: v for k, v in r.items() if keep(k)} for r in rows]
a, b = table("slurm"), table("local")
assert len(a) == 4 and a == b, (a, b)
PY
echo "sweep_slurm_test: ok (job $job)"

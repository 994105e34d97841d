#!/usr/bin/env bash
# Brings up a one-node Slurm cluster on this machine and runs the quick table2 study on it through
# study-slurm.sbatch: a job array of 3 shards, then a merge job that depends on it (afterok); waits for both and prints
# the merged report. For trying the Slurm scripts without a cluster (docs/cluster.md).
#
#   scripts/slurm-local.sh [--out DIR] [--keep]
#
# Needs root (slurmd runs jobs as root here). Installs FCT_SLURM_PACKAGES (slurm-wlm, munge) and builds FluoroCT
# (scripts/setup.sh); starts munged if no MUNGE daemon answers; writes slurm.conf (this host as controller and only
# compute node, no cgroups: proctrack/linuxproc, task/none, no accounting) into $FCT_SLURM_DIR (default
# /tmp/fluoroct-slurm) with its state, logs and job output, and starts slurmctld and slurmd from it. The study goes to
# DIR (default $FCT_SLURM_DIR/study-table2). The daemons it started are stopped at the end unless --keep is given
# (then: export SLURM_CONF=$FCT_SLURM_DIR/slurm.conf to use sinfo, squeue, sbatch).
set -euo pipefail

die() {
  echo "slurm-local: error: $*" >&2
  exit 2
}
say() { echo "slurm-local: $*"; }

slurm_dir=${FCT_SLURM_DIR:-/tmp/fluoroct-slurm}
out="" keep=0
while (($#)); do
  case $1 in
    --out) (($# >= 2)) || die "--out needs a folder"; out=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    *) die "unknown option '$1'; usage: slurm-local.sh [--out DIR] [--keep]" ;;
  esac
done
[[ $(id -u) -eq 0 ]] || die "run as root: slurmd and munged are started here and the jobs run as root"

source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"  # FluoroCT's packages and build
fct_install_packages "${FCT_SLURM_PACKAGES[@]}"
mkdir -p "$slurm_dir"/{state,spool,log,jobs}
slurm_dir=$(cd "$slurm_dir" && pwd)
out=$(realpath -m "${out:-$slurm_dir/study-table2}")
export SLURM_CONF=$slurm_dir/slurm.conf

started=()  # "name:pidfile" of the daemons this run started, stopped on exit unless --keep
stop_started() {
  ((keep)) && return 0
  local entry
  for entry in "${started[@]}"; do
    [[ -f ${entry#*:} ]] && kill "$(cat "${entry#*:}")" 2>/dev/null && say "stopped ${entry%%:*}"
  done
  return 0
}
trap stop_started EXIT

# MUNGE authenticates the daemons and commands; the Debian package made /etc/munge/munge.key.
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  [[ -s /etc/munge/munge.key ]] || mungekey --create --keyfile=/etc/munge/munge.key
  chown munge:munge /etc/munge/munge.key
  chmod 0400 /etc/munge/munge.key
  install -d -o munge -g munge -m 0755 /run/munge
  runuser -u munge -- /usr/sbin/munged
  started+=("munged:/run/munge/munged.pid")
  for _ in {1..20}; do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.5; done
  munge -n | unmunge >/dev/null || die "munged does not answer; see /var/log/munge/munged.log"
  say "started munged"
fi

host=$(hostname -s)
memory_mb=$(awk '/MemTotal/ { print int($2 / 1024 * 0.8) }' /proc/meminfo)
cat >"$SLURM_CONF" <<CONF
# One-node Slurm cluster for FluoroCT's study scripts (written by scripts/slurm-local.sh).
ClusterName=fluoroct-local
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
# No cgroups or systemd: processes are tracked by parent id, tasks are not bound.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
StateSaveLocation=$slurm_dir/state
SlurmdSpoolDir=$slurm_dir/spool
SlurmctldPidFile=$slurm_dir/slurmctld.pid
SlurmdPidFile=$slurm_dir/slurmd.pid
SlurmctldLogFile=$slurm_dir/log/slurmctld.log
SlurmdLogFile=$slurm_dir/log/slurmd.log
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$memory_mb State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF

# Starts daemon $1 (slurmctld or slurmd) from this configuration unless its pid file names a live process.
start_daemon() {
  local pidfile=$slurm_dir/$1.pid
  if [[ -f $pidfile ]] && kill -0 "$(cat "$pidfile")" 2>/dev/null; then
    say "$1 already running (pid $(cat "$pidfile"))"
    return
  fi
  "/usr/sbin/$1" -f "$SLURM_CONF" || die "$1 did not start; see $slurm_dir/log/$1.log"
  started+=("$1:$pidfile")
  say "started $1"
}
start_daemon slurmctld
sleep 1
start_daemon slurmd
for _ in {1..60}; do
  state=$(sinfo -h -n "$host" -o %T 2>/dev/null || true)
  [[ $state == idle || $state == mixed || $state == allocated ]] && break
  sleep 1
done
[[ ${state:-} == idle || ${state:-} == mixed || ${state:-} == allocated ]] ||
  die "node $host is '${state:-unknown}', not idle; see $slurm_dir/log/slurmctld.log and slurmd.log"
sinfo

cd "$FCT_ROOT"  # the submit folder: study-slurm.sbatch finds scripts/ and build/bin/fluoroct there
study=(table2 3 --quick --out "$out")
array=$(sbatch --parsable --array=1-3 --output="$slurm_dir/jobs/%x-%A_%a.out" scripts/study-slurm.sbatch "${study[@]}")
merge=$(sbatch --parsable --dependency=afterok:"$array" --output="$slurm_dir/jobs/%x-%j-merge.out" \
  scripts/study-slurm.sbatch "${study[@]}")
say "submitted array job $array (3 shards) and merge job $merge (--dependency=afterok:$array)"
squeue
for _ in {1..600}; do
  [[ -z $(squeue -h -j "$array,$merge" 2>/dev/null) ]] && break
  sleep 1
done
[[ -z $(squeue -h -j "$array,$merge" 2>/dev/null) ]] || die "jobs still queued after 10 minutes; see squeue"
failed=0
for job in "$array"_{1..3} "$merge"; do
  info=$(scontrol -o show job "$job")
  say "job $job: $(grep -o 'JobState=[A-Z_]*' <<<"$info") $(grep -o ' ExitCode=[0-9:]*' <<<"$info")"
  grep -q 'JobState=COMPLETED' <<<"$info" || failed=1
done
for log in "$slurm_dir"/jobs/*-"$array"_*.out "$slurm_dir/jobs/"*-"$merge"-merge.out; do
  echo "--- $log"
  tail -n 3 "$log"
done
((failed == 0)) && [[ -f $out/report.md ]] || die "a job did not complete or no merged report is in $out; see above"
echo "--- $out/report.md"
cat "$out/report.md"

#!/usr/bin/env bash
# Runs a FluoroCT evaluation study as N shards through GNU parallel, on this machine or on ssh hosts that see this
# file system at the same paths, then merges them into one trials.csv, report and charts (docs/cluster.md).
#
#   scripts/study-parallel.sh STUDY N --out DIR [--sshlogin LOGINS] [--shards-at-once J] [EVALUATE OPTIONS...]
#
# Shard K goes to DIR/shard-K-of-N, the merged study to DIR. --sshlogin is GNU parallel's (e.g. "2/node1,2/node2,:";
# may be repeated); --shards-at-once J runs J shards at once on each host (default: one per CPU core). EVALUATE
# OPTIONS go to every shard and to the merge. Re-running the same command resumes unfinished shards and merges again.
# Exits 2 without merging when a shard fails. The program is $FLUOROCT, else build/bin/fluoroct of this checkout.
set -euo pipefail

die() {
  echo "study-parallel: error: $*" >&2
  exit 2
}

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
(($# >= 2)) || die "usage: study-parallel.sh STUDY N --out DIR [--sshlogin LOGINS] [--shards-at-once J] [OPTIONS...]"
study=$1 shards=$2
shift 2
[[ $shards =~ ^[1-9][0-9]*$ ]] || die "N must be a positive number of shards, got '$shards'"
command -v parallel >/dev/null ||
  die "GNU parallel is not installed (Debian package 'parallel'; scripts/setup.sh installs it)"

parallel_options=() study_options=()
while (($#)); do
  case $1 in
    --sshlogin | -S) (($# >= 2)) || die "$1 needs logins"; parallel_options+=(--sshlogin "$2"); shift 2 ;;
    --shards-at-once) (($# >= 2)) || die "$1 needs a number"; parallel_options+=(--jobs "$2"); shift 2 ;;
    *) study_options+=("$1"); shift ;;
  esac
done
if [[ -n ${FLUOROCT_DATA_DIR:-} ]]; then parallel_options+=(--env FLUOROCT_DATA_DIR); fi
if [[ -n ${FLUOROCT:-} ]]; then parallel_options+=(--env FLUOROCT); fi

# Each shard's progress lines, tagged with the shard, as they come; the shards' folders keep their trials.
if ! parallel --quote --line-buffer --tagstring "shard {}/$shards" --workdir . "${parallel_options[@]}" \
  bash "$here/study-shard.sh" {} "$study" "$shards" "${study_options[@]}" ::: $(seq 1 "$shards"); then
  die "a shard failed (see its lines above); the finished trials are saved: re-run the same command to resume"
fi
exec bash "$here/study-shard.sh" merge "$study" "$shards" "${study_options[@]}"

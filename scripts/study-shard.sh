#!/usr/bin/env bash
# Runs shard K of N of a FluoroCT evaluation study, or merges the N shards: the one step that study-parallel.sh (GNU
# parallel) and study-slurm.sbatch (Slurm) run on each worker.
#
#   scripts/study-shard.sh K|merge STUDY N --out DIR [EVALUATE OPTIONS...]
#
# Shard K runs `fluoroct evaluate --study STUDY --shard K/N` into DIR/shard-K-of-N (resumable); `merge` merges
# DIR/shard-1-of-N ... DIR/shard-N-of-N into DIR (trials.csv, report.md, charts). EVALUATE OPTIONS (--quick, --trials,
# --preset, --detector, --ct, ...) must be the same for every shard and the merge. The program is $FLUOROCT, else
# build/bin/fluoroct of this checkout, else fluoroct on PATH.
set -euo pipefail

die() {
  echo "study-shard: error: $*" >&2
  exit 2
}

(($# >= 3)) || die "usage: study-shard.sh K|merge STUDY N --out DIR [EVALUATE OPTIONS...]"
step=$1 study=$2 shards=$3
shift 3
[[ $shards =~ ^[1-9][0-9]*$ ]] || die "N must be a positive number of shards, got '$shards'"
[[ $step == merge || ($step =~ ^[1-9][0-9]*$ && step -le shards) ]] ||
  die "the step must be a shard number from 1 to $shards or 'merge', got '$step'"

out="" options=()
while (($#)); do
  case $1 in
    --out) (($# >= 2)) || die "--out needs a folder"; out=$2; shift 2 ;;
    --out=*) out=${1#--out=}; shift ;;
    --shard | --shard=* | --merge | --merge=*) die "$1 is set by the shard scripts; leave it out" ;;
    *) options+=("$1"); shift ;;
  esac
done
[[ -n $out ]] || die "--out DIR is required (the shards go to DIR/shard-K-of-$shards, the merged study to DIR)"

fluoroct=${FLUOROCT:-}
if [[ -z $fluoroct ]]; then
  fluoroct="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/build/bin/fluoroct"
  [[ -x $fluoroct ]] || fluoroct=$(command -v fluoroct) || die "no fluoroct: build this checkout, put fluoroct on PATH or set FLUOROCT"
fi

if [[ $step == merge ]]; then
  folders=()
  for ((k = 1; k <= shards; ++k)); do folders+=("$out/shard-$k-of-$shards"); done
  exec "$fluoroct" evaluate --study "$study" "${options[@]}" --merge "${folders[@]}" --out "$out"
fi
exec "$fluoroct" evaluate --study "$study" "${options[@]}" --shard "$step/$shards" --out "$out/shard-$step-of-$shards"

#!/usr/bin/env bash
# Builds FluoroCT (installing any missing Debian packages) and runs the richest end-to-end job on the built-in
# phantom case, which needs no data: phantom CT -> standard C-arm views -> simulated X-rays at a known pose -> DRRs.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
BIN="$FCT_BUILD/bin"
OUT="${FCT_DEMO_DIR:-$FCT_BUILD/demo}"
rm -rf "$OUT"
mkdir -p "$OUT"
cd "$OUT"

echo "== 1. the built-in phantom CT"
"$BIN/fluoroct" phantom --out phantom.nrrd
"$BIN/fluoroct" info phantom.nrrd

echo "== 2. three standard C-arm views (AP, lateral, oblique) around the CT"
"$BIN/fluoroct" views --ct phantom.nrrd --out views.json --count 3

echo "== 3. simulated X-rays at a known bone pose (turned 5, -3, 4 deg about the bone centre, moved 6, -4, 5 mm)"
"$BIN/fluoroct" pose --ct phantom.nrrd --rotate-deg 5 -3 4 --translate-mm 6 -4 5 --out truth_pose.json
"$BIN/fluoroct" simulate --ct phantom.nrrd --views views.json --pose truth_pose.json --out case --noise-photons 20000 --seed 1

echo "== 4. DRRs at the truth pose, exact (Siddon) and from the Transgraph ray table"
"$BIN/fluoroct" drr --ct phantom.nrrd --views views.json --pose truth_pose.json --out drr_siddon.png
"$BIN/fluoroct" drr --ct phantom.nrrd --views views.json --pose truth_pose.json --method transgraph \
  --transgraph-cache "$OUT/transgraph_cache" --out drr_transgraph.png

echo "== demo output in $OUT"
ls "$OUT" "$OUT/case"

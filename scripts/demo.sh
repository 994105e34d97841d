#!/usr/bin/env bash
# Builds FluoroCT (installing any missing Debian packages) and runs the richest end-to-end job on the built-in
# phantom case, which needs no data: phantom CT -> standard C-arm views -> simulated X-rays at a known pose ->
# a start pose 10 mm away -> registration (fast preset) with the pose error, time and contour overlays -> DRRs.
#
# scripts/demo.sh --gui instead makes the built-in case for FluoroCT Studio (scripts/studio_case.sh) and opens it.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
if [[ "${1:-}" == "--gui" ]]; then
  CASE="${FCT_DEMO_DIR:-$FCT_BUILD/studio-case}"
  rm -rf "$CASE"
  "$FCT_ROOT/scripts/studio_case.sh" "$CASE"
  exec "$FCT_BUILD/bin/fluoroct-studio" --case "$CASE"
fi
BIN="$FCT_BUILD/bin"
OUT="${FCT_DEMO_DIR:-$FCT_BUILD/demo}"
rm -rf "$OUT"
mkdir -p "$OUT"
cd "$OUT"

echo "== 1. the built-in phantom CT"
"$BIN/fluoroct" phantom --out phantom.nrrd
"$BIN/fluoroct" info phantom.nrrd

echo "== 2. three standard C-arm views (AP, lateral, oblique) around the CT"
"$BIN/fluoroct" views --ct phantom.nrrd --out views.json --count 3 --detector 384x288 --pixel-mm 0.8

echo "== 3. simulated X-rays at a known bone pose (turned 5, -3, 4 deg about the bone centre, moved 6, -4, 5 mm)"
"$BIN/fluoroct" pose --ct phantom.nrrd --rotate-deg 5 -3 4 --translate-mm 6 -4 5 --out truth_pose.json
"$BIN/fluoroct" simulate --ct phantom.nrrd --views views.json --pose truth_pose.json --out case --noise-photons 20000 --seed 1

echo "== 4. a start pose 10 mm (mean bone-surface distance) away from the truth, as after a rough landmark setup"
"$BIN/fluoroct" pose --ct phantom.nrrd --from truth_pose.json --random-offset-mm 10 --seed 3 --out start_pose.json

echo "== 5. registration: NCC then VLNC, dynamic ROIs, pyramid, genetic search (fast preset)"
"$BIN/fluoroct" register --ct phantom.nrrd --views case/views.json --init start_pose.json --preset fast \
  --truth truth_pose.json --out result.json --overlays overlays

echo "== 6. DRRs at the registered pose, exact (Siddon) and from the Transgraph ray table"
"$BIN/fluoroct" drr --ct phantom.nrrd --views views.json --pose result.json --out drr_siddon.png
"$BIN/fluoroct" drr --ct phantom.nrrd --views views.json --pose result.json --method transgraph \
  --transgraph-cache "$OUT/transgraph_cache" --out drr_transgraph.png

echo "== demo output in $OUT"
ls "$OUT" "$OUT/case" "$OUT/overlays"

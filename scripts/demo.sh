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

echo "== 3. simulated X-rays at a known bone pose (5 deg, -3 deg, 4 deg; 6, -4, 5 mm), with quantum noise"
cat > truth_pose.json <<'JSON'
{"T_world_from_ct": [[0.99376, -0.07317, 0.08436, 6.0],
                     [0.06975, 0.99679, 0.03927, -4.0],
                     [-0.08696, -0.03324, 0.99566, 5.0],
                     [0, 0, 0, 1]]}
JSON
"$BIN/fluoroct" simulate --ct phantom.nrrd --views views.json --pose truth_pose.json --out case --noise-photons 20000 --seed 1

echo "== 4. DRRs at the truth pose, exact (Siddon) and from the Transgraph ray table"
"$BIN/fluoroct" drr --ct phantom.nrrd --views views.json --pose truth_pose.json --out drr_siddon.png
"$BIN/fluoroct" drr --ct phantom.nrrd --views views.json --pose truth_pose.json --method transgraph \
  --transgraph-cache "$OUT/transgraph_cache" --out drr_transgraph.png

echo "== demo output in $OUT"
ls "$OUT" "$OUT/case"

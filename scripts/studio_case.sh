#!/usr/bin/env bash
# Makes the built-in FluoroCT Studio case in a folder with the fluoroct CLI (no data needed): the phantom CT as
# ct.nrrd, three standard C-arm views with X-rays simulated at a known pose (views.json, *.png, truth_pose.json) and
# a start pose 10 mm (mean bone-surface distance) from the truth (initial_pose.json). Open it with
#   fluoroct-studio --case FOLDER
# Usage: scripts/studio_case.sh FOLDER   (FCT_BUILD_DIR picks the build; the CLI must be built)
set -euo pipefail
if [[ $# -ne 1 ]]; then
  echo "usage: $0 FOLDER" >&2
  exit 2
fi
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${FCT_BUILD_DIR:-$ROOT/build}/bin"
OUT="$1"
mkdir -p "$OUT"
"$BIN/fluoroct" phantom --out "$OUT/ct.nrrd"
"$BIN/fluoroct" views --ct "$OUT/ct.nrrd" --out "$OUT/camera.json" --count 3 --detector 384x288 --pixel-mm 0.8
"$BIN/fluoroct" pose --ct "$OUT/ct.nrrd" --rotate-deg 5 -3 4 --translate-mm 6 -4 5 --out "$OUT/truth.json"
"$BIN/fluoroct" simulate --ct "$OUT/ct.nrrd" --views "$OUT/camera.json" --pose "$OUT/truth.json" --out "$OUT" \
  --noise-photons 20000 --seed 1
"$BIN/fluoroct" pose --ct "$OUT/ct.nrrd" --from "$OUT/truth_pose.json" --random-offset-mm 10 --seed 3 \
  --out "$OUT/initial_pose.json"
rm -f "$OUT/camera.json" "$OUT/truth.json"
echo "studio case in $OUT: open it with fluoroct-studio --case $OUT"

#!/usr/bin/env bash
# Makes the built-in FluoroCT Studio case in a folder with the fluoroct CLI (no data needed): the phantom CT as
# ct.nrrd, three standard C-arm views with X-rays simulated at a known pose (views.json, *.png, truth_pose.json) and
# a start pose 10 mm (mean bone-surface distance) from the truth (initial_pose.json). Open it with
#   fluoroct-studio --case FOLDER
# With a CT (a volume file) as second argument, the case is made on that CT instead of the phantom, e.g.
#   scripts/studio_case.sh build/pelvis-case ../shared/data/ct/pelvis_totalseg.nii.gz
# Usage: scripts/studio_case.sh FOLDER [CT]   (FCT_BUILD_DIR picks the build; the CLI must be built)
set -euo pipefail
if [[ $# -lt 1 || $# -gt 2 ]]; then
  echo "usage: $0 FOLDER [CT volume file]" >&2
  exit 2
fi
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${FCT_BUILD_DIR:-$ROOT/build}/bin"
OUT="$1"
mkdir -p "$OUT"
if [[ $# -eq 2 ]]; then
  case "$2" in
    *.nii.gz) CT="$OUT/ct.nii.gz" ;;
    *) CT="$OUT/ct.${2##*.}" ;;
  esac
  cp "$2" "$CT"
else
  CT="$OUT/ct.nrrd"
  "$BIN/fluoroct" phantom --out "$CT"
fi
"$BIN/fluoroct" views --ct "$CT" --out "$OUT/camera.json" --count 3 --detector 384x288 --pixel-mm 0.8
"$BIN/fluoroct" pose --ct "$CT" --rotate-deg 5 -3 4 --translate-mm 6 -4 5 --out "$OUT/truth.json"
"$BIN/fluoroct" simulate --ct "$CT" --views "$OUT/camera.json" --pose "$OUT/truth.json" --out "$OUT" \
  --noise-photons 20000 --seed 1
"$BIN/fluoroct" pose --ct "$CT" --from "$OUT/truth_pose.json" --random-offset-mm 10 --seed 3 \
  --out "$OUT/initial_pose.json"
rm -f "$OUT/camera.json" "$OUT/truth.json"
echo "studio case in $OUT: open it with fluoroct-studio --case $OUT"

#!/usr/bin/env bash
# Builds FluoroCT, makes the built-in case and, when the shared data is there, the same case on the pelvis CT
# (ct/pelvis_totalseg.nii.gz), and saves a screenshot of FluoroCT Studio at each workflow step of each, under Xvfb,
# into a folder (default: build/screenshots): studio-<step>.png (built-in case) and pelvis-<step>.png; the Register
# and Review shots are taken after a registration run from the Register step (--register), the Track shot after that
# run and the tracking of a simulated 20-frame sequence of the case's views (--track, `fluoroct simulate --frames`).
# Steps the build does not have are skipped. The data folder is $FLUOROCT_DATA_DIR, else ../shared/data beside the repository.
# Usage: scripts/screenshots.sh [FOLDER]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
OUT="${1:-$FCT_BUILD/screenshots}"
DATA="${FLUOROCT_DATA_DIR:-$FCT_ROOT/../shared/data}"
mkdir -p "$OUT"

# shoot PREFIX CASE: one screenshot per step of the case folder CASE, named PREFIX-<step>.png.
shoot() {
  local prefix="$1" case="$2"
  "$FCT_BUILD/bin/fluoroct" simulate --ct "$(ls -d "$case"/ct.* "$case"/ct 2>/dev/null | head -1)" \
    --views "$case/views.json" --pose "$case/truth_pose.json" --out "$case/cine" --model physical --frames 20 \
    --noise-photons 20000 --motion-mm 4 --motion-deg 3 --motion-period-frames 30 > /dev/null
  for step in data initial-pose rois register review track; do
    extra=()
    [[ "$step" == register || "$step" == review ]] && extra=(--register)
    [[ "$step" == track ]] && extra=(--register --track "$case/cine/views.json")
    if xvfb-run -a -s "-screen 0 1600x1000x24" "$FCT_BUILD/bin/fluoroct-studio" --case "$case" --step "$step" \
        "${extra[@]}" --screenshot "$OUT/$prefix-$step.png" 2> "$OUT/.stderr"; then
      echo "wrote $OUT/$prefix-$step.png"
    elif grep -q "no step named" "$OUT/.stderr"; then
      echo "skipped step '$step' (not in this build)"
    else
      cat "$OUT/.stderr" >&2
      exit 1
    fi
  done
  rm -f "$OUT/.stderr"
}

CASE="$FCT_BUILD/studio-case"
rm -rf "$CASE"
"$FCT_ROOT/scripts/studio_case.sh" "$CASE" > /dev/null
shoot studio "$CASE"

PELVIS="$DATA/ct/pelvis_totalseg.nii.gz"
if [[ -f "$PELVIS" ]]; then
  CASE="$FCT_BUILD/studio-case-pelvis"
  rm -rf "$CASE"
  "$FCT_ROOT/scripts/studio_case.sh" "$CASE" "$PELVIS" > /dev/null
  shoot pelvis "$CASE"
else
  echo "skipped the pelvis case: $PELVIS not found (set FLUOROCT_DATA_DIR)"
fi

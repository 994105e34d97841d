#!/usr/bin/env bash
# Builds FluoroCT, makes the built-in case and saves a screenshot of FluoroCT Studio at each workflow step, under
# Xvfb, into a folder (default: build/screenshots): studio-<step>.png; the Register and Review shots are taken after a
# registration run from the Register step (--register). Steps the build does not have are skipped.
# Usage: scripts/screenshots.sh [FOLDER]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
OUT="${1:-$FCT_BUILD/screenshots}"
CASE="$FCT_BUILD/studio-case"
mkdir -p "$OUT"
rm -rf "$CASE"
"$FCT_ROOT/scripts/studio_case.sh" "$CASE" > /dev/null
for step in data initial-pose rois register review; do
  extra=()
  [[ "$step" == register || "$step" == review ]] && extra=(--register)
  if xvfb-run -a -s "-screen 0 1600x1000x24" "$FCT_BUILD/bin/fluoroct-studio" --case "$CASE" --step "$step" "${extra[@]}" \
      --screenshot "$OUT/studio-$step.png" 2> "$OUT/.stderr"; then
    echo "wrote $OUT/studio-$step.png"
  elif grep -q "no step named" "$OUT/.stderr"; then
    echo "skipped step '$step' (not in this build)"
  else
    cat "$OUT/.stderr" >&2
    exit 1
  fi
done
rm -f "$OUT/.stderr"

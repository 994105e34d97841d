#!/usr/bin/env bash
# The bias of the optimum: registration started at the true pose of Table 2's trials (the studies' X-rays: continuous
# patient, 80 kVp spectrum, scatter haze, noise, PSF, vignetting; the ideal scenario by default: no tools, the original
# CT; realistic and bad: K-wires and screws not in the CT, and the CT of 2.4 or 4.2 mm slices the case writes where
# the scenario's slices differ from the CT's own, as the pelvis's realistic 3 mm ones do not), with one or more presets.
# Writes each trial once as a case (`fluoroct evaluate --write-trial`, kept in the work folder and reused), registers
# it from its truth (`fluoroct register --init truth_pose.json --cut-face-margin-mm 5` with the trial's seed and CT, as
# the study does) and prints, per preset and CT, the mean and largest final error (mean bone-surface distance to the
# truth) and how many trials end more than 0.1 mm off; one line per registration goes to WORK/start-at-truth.csv.
# Usage: scripts/start-at-truth.sh --preset P [--preset P ...] [--ct pelvis|head ...] [--trials "0 1 2 ..."]
#                                  [--scenario ideal|realistic|bad] [--detector 512x512] [--pixel-mm 0.45] [--jobs 2]
#                                  [--work DIR]
# Defaults: both CTs, pelvis trials 0-19, head trials 0-7, the ideal scenario, 512x512 at 0.45 mm, 2 jobs,
# WORK = /tmp/fluoroct-start-at-truth. Environment: BUILD_DIR (default build), FLUOROCT_DATA_DIR (default
# ../shared/data beside the source tree).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"
DATA="${FLUOROCT_DATA_DIR:-$ROOT/../shared/data}"
PRESETS=() CTS=() TRIALS="" SCENARIO=ideal DETECTOR=512x512 PIXEL_MM=0.45 JOBS=2 WORK=/tmp/fluoroct-start-at-truth
while (($#)); do
  case "$1" in
    --preset) PRESETS+=("$2"); shift ;;
    --ct) CTS+=("$2"); shift ;;
    --trials) TRIALS="$2"; shift ;;
    --scenario) SCENARIO="$2"; shift ;;
    --detector) DETECTOR="$2"; shift ;;
    --pixel-mm) PIXEL_MM="$2"; shift ;;
    --jobs) JOBS="$2"; shift ;;
    --work) WORK="$2"; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "error: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done
((${#PRESETS[@]})) || { echo "error: give at least one --preset (a built-in name or a preset file)" >&2; exit 2; }
((${#CTS[@]})) || CTS=(pelvis head)
for ct in "${CTS[@]}"; do
  [[ "$ct" == pelvis || "$ct" == head ]] || { echo "error: --ct must be pelvis or head, got '$ct'" >&2; exit 2; }
done
[[ "$SCENARIO" =~ ^(ideal|realistic|bad)$ ]] ||
  { echo "error: --scenario must be ideal, realistic or bad, got '$SCENARIO'" >&2; exit 2; }
[[ -d "$DATA/ct" ]] || { echo "error: no CT folder at $DATA/ct; set FLUOROCT_DATA_DIR" >&2; exit 2; }
for i in "${!PRESETS[@]}"; do  # preset files as absolute paths: the registrations run from the work folder's cases
  [[ -f "${PRESETS[$i]}" ]] && PRESETS[$i]="$(cd "$(dirname "${PRESETS[$i]}")" && pwd)/$(basename "${PRESETS[$i]}")"
done

FCT_BUILD_DIR="$BUILD_DIR" FCT_BUILD_TARGETS=(fluoroct)
source "$ROOT/scripts/setup.sh" > /dev/null  # the project's packages and build (fct_build), only `fluoroct`
export FCT="$BUILD_DIR/bin/fluoroct" DATA SCENARIO DETECTOR PIXEL_MM WORK
mkdir -p "$WORK"
echo "start at the truth: $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, commit" \
  "$(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown), $SCENARIO scenario," \
  "$DETECTOR at $PIXEL_MM mm, work folder $WORK"

# ct_path CT / ct_study CT: the CT file and the name the study gives it.
ct_path() { [[ "$1" == pelvis ]] && echo "$DATA/ct/pelvis_totalseg.nii.gz" || echo "$DATA/ct/head_phantom_philips_bone"; }
ct_study() { [[ "$1" == pelvis ]] && echo pelvis_totalseg || echo head_phantom_philips_bone; }
export -f ct_path ct_study

# trial_seed DIR: the trial's seed, from the register command that --write-trial printed into DIR.log.
trial_seed() {
  local seed
  seed="$(grep -o -- '--seed [0-9]*' "$1.log" 2>/dev/null | head -1 | awk '{print $2}')"
  [[ -n "$seed" ]] || { echo "error: no trial seed in $1.log; delete $1 to write the case again" >&2; return 1; }
  echo "$seed"
}
# write_case CT TRIAL: the trial's case folder, written once; fails when its seed cannot be read back.
write_case() {
  local ct="$1" trial="$2" dir="$WORK/$DETECTOR/$1-$SCENARIO-$2"
  if [[ ! -f "$dir/truth_pose.json" ]]; then
    "$FCT" evaluate --study table2 --detector "$DETECTOR" --pixel-mm "$PIXEL_MM" --ct "$(ct_path "$ct")" \
      --write-trial "$(ct_study "$ct")/$SCENARIO:$trial" --out "$dir" > "$dir.log" 2>&1 ||
      { echo "error: writing $ct trial $trial failed; see $dir.log" >&2; return 1; }
  fi
  trial_seed "$dir" > /dev/null
}
# register_case PRESET CT TRIAL: one registration from the truth; prints a CSV line.
register_case() {
  local preset="$1" ct="$2" trial="$3" dir="$WORK/$DETECTOR/$2-$SCENARIO-$3"
  local out="$dir.$(basename "$preset" .json)" seed ct_file="$(ct_path "$2")"
  seed="$(trial_seed "$dir")" || return 1
  [[ -f "$dir/ct_registration.nrrd" ]] && ct_file="$dir/ct_registration.nrrd"  # the scenario's thick-slice CT
  "$FCT" register --ct "$ct_file" --views "$dir/views.json" --init "$dir/truth_pose.json" \
    --truth "$dir/truth_pose.json" --preset "$preset" --cut-face-margin-mm 5 --seed "$seed" \
    --out "$out.json" > "$out.log" 2>&1 || { echo "error: registering $ct trial $trial failed; see $out.log" >&2; return 1; }
  local error_mm
  error_mm="$(grep 'pose error vs truth' "$out.log" | sed -E 's/.*-> ([0-9.]+) mm.*/\1/')"
  [[ -n "$error_mm" ]] || { echo "error: no pose error in $out.log (registering $ct trial $trial)" >&2; return 1; }
  echo "$(basename "$preset" .json),$ct,$trial,$error_mm"
}
export -f trial_seed write_case register_case

tasks=()
for ct in "${CTS[@]}"; do
  trials="$TRIALS"
  [[ -n "$trials" ]] || { [[ "$ct" == pelvis ]] && trials="$(seq 0 19 | xargs)" || trials="$(seq 0 7 | xargs)"; }
  for t in $trials; do tasks+=("$ct $t"); done
done
mkdir -p "$WORK/$DETECTOR"
printf '%s\n' "${tasks[@]}" | xargs -P "$JOBS" -L 1 bash -c 'write_case "$1" "$2"' _
CSV="$WORK/start-at-truth.csv"
echo "preset,ct,trial,final_error_mm" > "$CSV"
for preset in "${PRESETS[@]}"; do
  printf '%s\n' "${tasks[@]}" | xargs -P "$JOBS" -L 1 bash -c 'register_case "$1" "$2" "$3"' _ "$preset" >> "$CSV"
done
echo "preset,ct,trials,mean_mm,max_mm,above_0.1_mm"
tail -n +2 "$CSV" | sort -t, -k1,2 | awk -F, '
  { key = $1 "," $2; n[key]++; s[key] += $4; if ($4 > m[key]) m[key] = $4; if ($4 > 0.1) k[key]++ }
  END { for (key in n) printf "%s,%d,%.3f,%.3f,%d\n", key, n[key], s[key] / n[key], m[key], k[key] }' | sort
echo "per registration: $CSV"

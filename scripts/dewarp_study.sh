#!/usr/bin/env bash
# Registration on simulated image-intensifier X-rays with and without the dewarp, and on the same case without
# distortion (docs/registration.md#image-intensifier-dewarp). Physical simulator, three standard views (384x288 at
# 0.8 mm), pincushion 0.06 and S-distortion 4 deg, a grid plate image per view (10 mm pitch) calibrated with
# `fluoroct dewarp-calibrate`, then `register --preset fast` from five starts 10 mm (mean bone-surface distance) from
# the truth, on the undistorted, the distorted and the dewarped views. Prints one line per registration and a
# summary table. Needs python3 (to add the views' "dewarp" keys and to summarise).
# Usage: scripts/dewarp_study.sh FOLDER [CT]   (default CT: the built-in phantom; FCT_BUILD_DIR picks the build)
set -euo pipefail
if [[ $# -lt 1 || $# -gt 2 ]]; then
  echo "usage: $0 FOLDER [CT volume file]" >&2
  exit 2
fi
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${FCT_BUILD_DIR:-$ROOT/build}/bin"
OUT="$1"
CT="${2:-$OUT/phantom.nrrd}"
mkdir -p "$OUT"
[[ $# -eq 2 ]] || "$BIN/fluoroct" phantom --out "$CT"
"$BIN/fluoroct" views --ct "$CT" --out "$OUT/views.json" --count 3 --detector 384x288 --pixel-mm 0.8
"$BIN/fluoroct" pose --ct "$CT" --rotate-deg 5 -3 4 --translate-mm 6 -4 5 --out "$OUT/truth_pose.json"
SIMULATE=("$BIN/fluoroct" simulate --model physical --ct "$CT" --views "$OUT/views.json" --pose "$OUT/truth_pose.json"
          --dose 20000 --psf-px 0.7 --vignetting 0.2 --seed 1)
"${SIMULATE[@]}" --out "$OUT/ideal"
"${SIMULATE[@]}" --out "$OUT/case" --pincushion 0.06 --s-distortion-deg 4 --grid-pitch-mm 10
for view in ap lateral oblique45; do
  "$BIN/fluoroct" dewarp-calibrate "$OUT/case/${view}_grid.png" --pitch-mm 10 --pixel-spacing-mm 0.8 \
    --out "$OUT/case/${view}.dewarp.json"
done
python3 - "$OUT/case" <<'PY'
import json, sys
views = json.load(open(f"{sys.argv[1]}/views.json"))
for view in views["views"]:
    view["dewarp"] = view["name"] + ".dewarp.json"
json.dump(views, open(f"{sys.argv[1]}/views_dewarped.json", "w"), indent=2)
PY
for seed in 1 2 3 4 5; do
  "$BIN/fluoroct" pose --ct "$CT" --from "$OUT/truth_pose.json" --random-offset-mm 10 --seed "$seed" \
    --out "$OUT/start_$seed.json"
  for mode in undistorted distorted dewarped; do
    case $mode in
      undistorted) views="$OUT/ideal/views.json" ;;
      distorted) views="$OUT/case/views.json" ;;
      dewarped) views="$OUT/case/views_dewarped.json" ;;
    esac
    "$BIN/fluoroct" register --ct "$CT" --views "$views" --init "$OUT/start_$seed.json" --preset fast \
      --truth "$OUT/truth_pose.json" --out "$OUT/result_${mode}_$seed.json" > "$OUT/log_${mode}_$seed.txt" 2>&1
    grep "pose error vs truth" "$OUT/log_${mode}_$seed.txt" | sed "s/^/$mode start $seed: /"
  done
done
python3 - "$OUT" <<'PY'
import glob, re, statistics, sys
print("| images | runs | sTRE mean, average (mm) | median | worst | sTRE max, worst (mm) | final mean sTRE < 2 mm |")
print("| --- | --- | --- | --- | --- | --- | --- |")
for mode in ("undistorted", "distorted", "dewarped"):
    means, maxima = [], []
    for log in sorted(glob.glob(f"{sys.argv[1]}/log_{mode}_*.txt")):
        found = re.search(r"-> ([0-9.]+) mm \(max ([0-9.]+) mm\)", open(log).read())
        means.append(float(found.group(1)))
        maxima.append(float(found.group(2)))
    print(f"| {mode} | {len(means)} | {statistics.mean(means):.3f} | {statistics.median(means):.3f} | "
          f"{max(means):.3f} | {max(maxima):.3f} | {sum(m < 2.0 for m in means)}/{len(means)} |")
PY

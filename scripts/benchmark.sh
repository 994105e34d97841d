#!/usr/bin/env bash
# The speed benchmark in one command: builds what it needs, then prints
#  1. registration time and error (mean bone-surface distance to the truth) of the default preset, of `paper` and of a
#     no-tricks baseline (Testing/Benchmarks/baseline.json) on 3 views of 512x512 (0.45 mm pixels) of the head
#     phantom CT and the pelvis CT, X-rays from the physical simulator (`fluoroct simulate --model physical`),
#     starts 10 mm from the truth; medians over the starts, and time ratios against `paper` measured in the same run;
#  2. whole-process DRR time of `fluoroct drr` against `plastimatch drr -A cpu -i exact` on 8 views of 800x600 of the
#     head phantom, with the NCC between the two programs' images (Testing/Benchmarks/DrrBenchmark --whole-process).
# With --scaling it prints instead the default preset's time and peak memory against detector size, view count and
# CT size.
# Usage: scripts/benchmark.sh [--starts N] [--baseline-starts N (0: no baseline)] [--drr-repeats N] [--no-drr] [--no-registration]
#                             [--scaling] [--work DIR (kept, with the simulated cases)]
# Environment: BUILD_DIR (default build), FLUOROCT_DATA_DIR (default ../shared/data beside the source tree).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"
DATA="${FLUOROCT_DATA_DIR:-$ROOT/../shared/data}"
STARTS=3 BASELINE_STARTS=1 DRR_REPEATS=3 DRR=1 REGISTRATION=1 SCALING=0
WORK="" KEEP=0
while (($#)); do
  case "$1" in
    --starts) STARTS="$2"; shift ;;
    --baseline-starts) BASELINE_STARTS="$2"; shift ;;
    --drr-repeats) DRR_REPEATS="$2"; shift ;;
    --no-drr) DRR=0 ;;
    --no-registration) REGISTRATION=0 ;;
    --scaling) SCALING=1 ;;
    --work) WORK="$2"; KEEP=1; shift ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "error: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done

if [[ ! -f "$BUILD_DIR/CMakeCache.txt" ]]; then
  cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
fi
cmake --build "$BUILD_DIR" -j"${FCT_JOBS:-2}" --target fluoroct DrrBenchmark > /dev/null
FCT="$BUILD_DIR/bin/fluoroct"
if ((KEEP)); then
  mkdir -p "$WORK"
else
  WORK="$(mktemp -d "${TMPDIR:-/tmp}/fluoroct-benchmark.XXXXXX")"
  trap 'rm -rf "$WORK"' EXIT
fi

echo "benchmark: $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | xargs)"
echo "load at start: $(uptime | sed 's/.*load average/load average/')"
echo "commit: $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)"

median() { sort -g | awk '{v[NR]=$1} END {if (NR == 0) print "nan"; else if (NR % 2) print v[(NR+1)/2]; else printf "%.3f\n", (v[NR/2]+v[NR/2+1])/2}'; }

# make_case NAME CT COLS ROWS PIXEL_MM COUNT: a simulated case in $WORK/NAME (views, truth, physical X-rays, starts).
make_case() {
  local name="$1" ct="$2" cols="$3" rows="$4" pixel="$5" count="$6" dir="$WORK/$1"
  mkdir -p "$dir"
  "$FCT" views --ct "$ct" --out "$dir/views.json" --count "$count" --detector "${cols}x${rows}" --pixel-mm "$pixel" > /dev/null
  "$FCT" pose --ct "$ct" --rotate-deg 4 -3 6 --translate-mm 2 -3 1.5 --out "$dir/truth.json" > /dev/null
  "$FCT" simulate --ct "$ct" --views "$dir/views.json" --pose "$dir/truth.json" --out "$dir/case" --model physical \
    --seed 1 > /dev/null
  local s
  for ((s = 1; s <= STARTS; s++)); do
    "$FCT" pose --ct "$ct" --from "$dir/truth.json" --random-offset-mm 10 --seed "$((100 + s))" --out "$dir/start$s.json" > /dev/null
  done
}

# register NAME CT START LABEL [ARGS...]: one registration; prints "seconds drrs error_mm peak_MB cpu_s" (cpu_s: user +
# system time of the whole process, CT load included: less sensitive to the machine's load than the wall time).
register() {
  local name="$1" ct="$2" start="$3" label="$4" dir="$WORK/$1"
  shift 4
  local log="$dir/$label-$(basename "$start" .json).log"
  /usr/bin/time -f 'peak_kb %M cpu_s %U %S' "$FCT" register --ct "$ct" --views "$dir/case/views.json" --init "$start" \
    --truth "$dir/truth.json" --out "$dir/result.json" "$@" > "$log" 2>&1 || { echo "nan nan nan nan nan"; return; }
  awk '/^registered in/ {t=$3; d=$5} /pose error vs truth/ {for (i = 1; i < NF; i++) if ($i == "->") e = $(i + 1)} /^peak_kb/ {m=$2/1024; c=$4+$5}
       END {printf "%s %s %s %.0f %.2f\n", t, d, e, m, c}' "$log"
}

# run_config NAME CT LABEL STARTS [ARGS...]: registrations from the first STARTS starts; prints the summary line.
declare -A MEDIAN_TIME MEDIAN_ERROR
run_config() {
  local name="$1" ct="$2" label="$3" starts="$4"
  shift 4
  local s out times="" errors="" drrs="" peaks="" cpus=""
  for ((s = 1; s <= starts; s++)); do
    out=$(register "$name" "$ct" "$WORK/$name/start$s.json" "$label" "$@")
    read -r t d e m c <<< "$out"
    printf '  %-10s %-8s start %d: %8s s %7s DRRs  error %7s mm  peak %5s MB  process cpu %7s s\n' "$name" "$label" \
      "$s" "$t" "$d" "$e" "$m" "$c"
    times+="$t"$'\n' errors+="$e"$'\n' drrs+="$d"$'\n' peaks+="$m"$'\n' cpus+="$c"$'\n'
  done
  local mt me md mp mc
  mt=$(printf '%s' "$times" | median) me=$(printf '%s' "$errors" | median)
  md=$(printf '%s' "$drrs" | median) mp=$(printf '%s' "$peaks" | sort -g | tail -1) mc=$(printf '%s' "$cpus" | median)
  MEDIAN_TIME["$name/$label"]="$mt"
  MEDIAN_ERROR["$name/$label"]="$me"
  SUMMARY+=("$(printf '| %s | %s | %d | %s s | %s s | %s | %s mm | %s MB |' "$name" "$label" "$starts" "$mt" "$mc" "$md" \
    "$me" "$mp")")
}

CTS=("head:$DATA/ct/head_phantom_philips_bone" "pelvis:$DATA/ct/pelvis_totalseg.nii.gz")
SUMMARY=()

if ((SCALING)); then
  echo
  echo "== scaling of the default preset (1 start, 10 mm; time excludes CT load; peak = whole process RSS)"
  STARTS=1
  head_ct="$DATA/ct/head_phantom_philips_bone"
  for size in 256 512 768 1024; do
    make_case "head-$size" "$head_ct" "$size" "$size" "$(awk -v s="$size" 'BEGIN {printf "%.3f", 0.45 * 512 / s}')" 3
    run_config "head-$size" "$head_ct" default 1
  done
  for count in 1 2 3 4 5; do
    make_case "head-v$count" "$head_ct" 512 512 0.45 "$count"
    run_config "head-v$count" "$head_ct" default 1
  done
  # The head CT at full and at half resolution (every second voxel along each axis), and resampled to 512x512x400
  # (0.35 mm slices, the memory case: it must register in <= 2 GB), with plastimatch resample.
  if command -v plastimatch > /dev/null; then
    plastimatch convert --input "$head_ct" --output-img "$WORK/head_full.mha" > /dev/null 2>&1
    plastimatch resample --input "$WORK/head_full.mha" --output "$WORK/head_half.mha" --subsample "2 2 2" > /dev/null 2>&1
    plastimatch resample --input "$WORK/head_full.mha" --output "$WORK/head_400.mha" --dim "512 512 400" \
      --spacing "$(plastimatch header "$WORK/head_full.mha" | awk '/^Spacing/ {print $3, $4}') 0.35" > /dev/null 2>&1
    for res in full half 400; do
      make_case "head-$res" "$WORK/head_$res.mha" 512 512 0.45 3
      run_config "head-$res" "$WORK/head_$res.mha" default 1
    done
  else
    echo "  CT size rows skipped: plastimatch (for the resampling) not found"
  fi
  echo
  echo "| case | preset | starts | median time | median process CPU | median DRRs | median error | peak memory |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
  printf '%s\n' "${SUMMARY[@]}"
  echo "load at end: $(uptime | sed 's/.*load average/load average/')"
  exit 0
fi

if ((REGISTRATION)); then
  echo
  echo "== registration: 3 views 512x512 at 0.45 mm, physical X-rays, starts 10 mm from the truth ($STARTS starts;" \
       "baseline $BASELINE_STARTS)"
  for entry in "${CTS[@]}"; do
    name="${entry%%:*}" ct="${entry#*:}"
    if [[ ! -e "$ct" ]]; then echo "  $name skipped: $ct not found"; continue; fi
    make_case "$name" "$ct" 512 512 0.45 3
    run_config "$name" "$ct" default "$STARTS"
    run_config "$name" "$ct" paper "$STARTS" --preset paper
    if ((BASELINE_STARTS > 0)); then
      run_config "$name" "$ct" baseline "$BASELINE_STARTS" --preset "$ROOT/Testing/Benchmarks/baseline.json"
    fi
  done
  echo
  echo "| case | preset | starts | median time | median process CPU | median DRRs | median error | peak memory |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
  printf '%s\n' "${SUMMARY[@]}"
  for entry in "${CTS[@]}"; do
    name="${entry%%:*}"
    [[ -n "${MEDIAN_TIME[$name/default]:-}" ]] || continue
    awk -v n="$name" -v d="${MEDIAN_TIME[$name/default]}" -v p="${MEDIAN_TIME[$name/paper]}" \
        -v b="${MEDIAN_TIME[$name/baseline]:-nan}" \
        -v ed="${MEDIAN_ERROR[$name/default]}" -v ep="${MEDIAN_ERROR[$name/paper]}" \
        'BEGIN {printf "ratio paper/default time %s: %.2f\n", n, p/d;
                if (b != "nan") printf "ratio baseline/default time %s: %.2f\n", n, b/d;
                printf "error default-paper %s: %+.3f mm (target <= +0.05)\n", n, ed-ep}'
  done
fi

if ((DRR)); then
  echo
  FLUOROCT_DATA_DIR="$DATA" "$BUILD_DIR/bin/DrrBenchmark" --whole-process 8 --repeats "$DRR_REPEATS" \
    --work "$WORK/drr"
fi
echo "load at end: $(uptime | sed 's/.*load average/load average/')"

#!/usr/bin/env bash
# Fuzzes every loader a user feeds with libFuzzer (docs/robustness.md "Fuzzing").
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET ...]        (default 60 s; default targets: all)
#   FCT_FUZZ_RUNS=N scripts/fuzz.sh 0 nifti                  (N executions instead of a time limit)
#   FCT_FUZZ_JOBS=2 scripts/fuzz.sh 600                      (two targets at once, e.g. one per core)
#
# Installs FCT_FUZZ_PACKAGES (clang-14, libfuzzer-14-dev, dcmtk) and does the normal build (scripts/setup.sh), then
# builds the fuzz programs with clang into build-fuzz/ (-fsanitize=fuzzer,address,undefined), makes the seed corpora
# in build-fuzz/fuzz/seeds/<target>/ (the project's writers, the fluoroct CLI, ../shared/data in every transfer
# syntax DCMTK writes, Testing/Fuzz/regressions), and runs the targets one after another (FCT_FUZZ_JOBS at
# once), nice'd, each in one process. New inputs collect in build-fuzz/fuzz/corpus/<target>/ (kept for the next run); a crash, leak,
# timeout or out-of-memory input is kept in build-fuzz/fuzz/crashes/<target>/ and ends that target's run.
# Prints per target the executions and the inputs kept as crashes; exits 1 when any target crashed.
# Reproduce a kept input: FCT_FUZZ_TARGET=<target> build-fuzz/bin/fluoroct_fuzz <file> (session: fluoroct_fuzz_studio);
# FCT_FUZZ_VERBOSE=1 prints what each loader said.
set -euo pipefail

seconds=${1:-60}
(($# > 0)) && shift
[[ $seconds =~ ^[0-9]+$ ]] || { echo "fuzz: SECONDS_PER_TARGET must be a whole number, got '$seconds'" >&2; exit 2; }
runs=${FCT_FUZZ_RUNS:--1}
if ((seconds == 0 && runs < 0)); then
  echo "fuzz: give SECONDS_PER_TARGET > 0 or FCT_FUZZ_RUNS" >&2
  exit 2
fi

source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"  # packages and the normal build (the seed writer, the CLI)
fct_install_packages "${FCT_FUZZ_PACKAGES[@]}"

all_targets=(dicom_slice dicom_series xray_dicom nifti nrrd nhdr mha mhd xray_png xray_tiff view pose landmark
  landmark_pair preset tfm transgraph_cache dewarp session)
targets=("$@")
((${#targets[@]})) || targets=("${all_targets[@]}")
for t in "${targets[@]}"; do
  [[ " ${all_targets[*]} " == *" $t "* ]] || { echo "fuzz: unknown target '$t'; targets: ${all_targets[*]}" >&2; exit 2; }
done

# --- the clang build -------------------------------------------------------------------------------------------
fuzz_build="$FCT_ROOT/build-fuzz"
sanitize="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
if [[ ! -f "$fuzz_build/build.ninja" ]]; then
  cmake -S "$FCT_ROOT" -B "$fuzz_build" -G Ninja -DFCT_FUZZ=ON -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
    "-DCMAKE_C_FLAGS=$sanitize" "-DCMAKE_CXX_FLAGS=$sanitize" "-DCMAKE_C_FLAGS_DEBUG=-O1 -g" \
    "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g" "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined"
fi
programs=(fluoroct_fuzz)
[[ " ${targets[*]} " == *" session "* ]] && programs+=(fluoroct_fuzz_studio)
nice cmake --build "$fuzz_build" -j "${FCT_JOBS:-1}" --target "${programs[@]}"

# --- seed corpora ----------------------------------------------------------------------------------------------
work="$fuzz_build/fuzz"
seeds="$work/seeds"
rm -rf "$seeds"
mkdir -p "$seeds"
QT_QPA_PLATFORM=offscreen "$FCT_BUILD/bin/fluoroct_fuzz_seeds" "$seeds"
cp -r "$FCT_ROOT/Testing/Fuzz/regressions/." "$seeds/"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fluoroct="$FCT_BUILD/bin/fluoroct"
# A small simulated case made by the CLI: CT, two views with images, poses.
"$fluoroct" phantom --out "$tmp/phantom.nrrd" --dims 24 24 20 --spacing-mm 4 >/dev/null
"$fluoroct" views --ct "$tmp/phantom.nrrd" --out "$tmp/camera.json" --count 2 --detector 16x12 --pixel-mm 20 >/dev/null
"$fluoroct" pose --ct "$tmp/phantom.nrrd" --rotate-deg 5 -3 4 --translate-mm 6 -4 5 --out "$tmp/truth.json" >/dev/null
"$fluoroct" simulate --ct "$tmp/phantom.nrrd" --views "$tmp/camera.json" --pose "$tmp/truth.json" --out "$tmp/case" \
  --noise-photons 20000 --seed 1 >/dev/null
cp "$tmp/phantom.nrrd" "$seeds/nrrd/cli_phantom.nrrd"
cp "$tmp/case/views.json" "$seeds/view/cli_views.json"
cp "$tmp/case/truth_pose.json" "$seeds/pose/cli_truth_pose.json"
cp "$tmp/case/ap.png" "$seeds/xray_png/cli_ap.png"

data="${FLUOROCT_DATA_DIR:-$FCT_ROOT/../shared/data}"
# DICOM in the transfer syntaxes DCMTK writes: explicit/implicit little endian, explicit big endian, deflated,
# JPEG baseline (8 bit) and lossless, JPEG-LS lossless and near-lossless, RLE.
transcode() {  # transcode IN OUTSTEM: OUTSTEM_<syntax>.dcm for each syntax that accepts the image
  local in=$1 out=$2
  dcmconv +te "$in" "${out}_explicit.dcm" 2>/dev/null || true
  dcmconv +ti "$in" "${out}_implicit.dcm" 2>/dev/null || true
  dcmconv +tb "$in" "${out}_bigendian.dcm" 2>/dev/null || true
  dcmconv +td "$in" "${out}_deflated.dcm" 2>/dev/null || true
  dcmcjpeg +eb "$in" "${out}_jpeg_baseline.dcm" 2>/dev/null || true
  dcmcjpeg +e1 "$in" "${out}_jpeg_lossless.dcm" 2>/dev/null || true
  dcmcjpls +el "$in" "${out}_jpegls_lossless.dcm" 2>/dev/null || true
  dcmcjpls +en "$in" "${out}_jpegls_near.dcm" 2>/dev/null || true
  dcmcrle "$in" "${out}_rle.dcm" 2>/dev/null || true
}
small() {  # small IN OUT PIXELS: the image scaled to PIXELS columns, uncompressed, private tags removed
  dcmdjpeg "$1" "$tmp/decoded.dcm" 2>/dev/null || cp "$1" "$tmp/decoded.dcm"
  dcmscale +Sxv "$3" "$tmp/decoded.dcm" "$2" 2>/dev/null && dcmodify -ep -nb "$2" 2>/dev/null
}
if [[ -d $data/xray ]]; then
  for f in "$data"/xray/*.dcm; do
    name=$(basename "$f" .dcm)
    small "$f" "$tmp/$name.dcm" 64 && transcode "$tmp/$name.dcm" "$seeds/xray_dicom/$name"
  done
  cp "$data/xray/dx_thorax_canine.dcm" "$seeds/xray_dicom/"
else
  echo "fuzz: $data/xray not found: the X-ray DICOM seeds are only the tiny kept ones"
fi
separator=FCTFUZZNEXTFILE
for series in head_phantom_philips_bone head_phantom_philips_tilted head_ge_irregular; do
  [[ -d $data/ct/$series ]] || { echo "fuzz: $data/ct/$series not found: no seeds from it"; continue; }
  mapfile -t files < <(find "$data/ct/$series" -type f | sort | head -3)
  small "${files[0]}" "$tmp/slice.dcm" 32 && transcode "$tmp/slice.dcm" "$seeds/dicom_slice/$series"
  for n in 0 1 2; do small "${files[$n]}" "$tmp/s$n.dcm" 32 && transcode "$tmp/s$n.dcm" "$tmp/s$n"; done
  for f in "$tmp"/s0_*.dcm; do
    syntax=${f#"$tmp"/s0_}
    [[ -f $tmp/s1_$syntax && -f $tmp/s2_$syntax ]] || continue
    { cat "$f"; printf %s "$separator"; cat "$tmp/s1_$syntax"; printf %s "$separator"; cat "$tmp/s2_$syntax"; } \
      >"$seeds/dicom_series/${series}_$syntax"
  done
  rm -f "$tmp"/s[0-2]*.dcm
done
if [[ -f $data/ct/pelvis_totalseg.nii.gz ]]; then
  plastimatch convert --input "$data/ct/pelvis_totalseg.nii.gz" --output-img "$tmp/pelvis.mha" --output-type short \
    >/dev/null
  plastimatch resample --input "$tmp/pelvis.mha" --output "$tmp/pelvis_small.mha" --dim "10 8 8" --output-type short \
    >/dev/null
  for out in "nifti/pelvis_small.nii" "nifti/pelvis_small.nii.gz" "nrrd/pelvis_small_itk.nrrd" "mha/pelvis_small_itk.mha"; do
    plastimatch convert --input "$tmp/pelvis_small.mha" --output-img "$seeds/$out" >/dev/null
  done
fi

# --- the runs --------------------------------------------------------------------------------------------------
# FCT_FUZZ_JOBS targets run at once (default 1), each in one process.
jobs=${FCT_FUZZ_JOBS:-1}
[[ $jobs =~ ^[1-9][0-9]*$ ]] || { echo "fuzz: FCT_FUZZ_JOBS must be a whole number >= 1, got '$jobs'" >&2; exit 2; }
run_target() {  # run_target TARGET: fuzzes it and writes its summary line to $tmp/summary-TARGET
  local t=$1 program="$fuzz_build/bin/fluoroct_fuzz" log="$work/$1.log" status executions kept
  [[ $t == session ]] && program="$fuzz_build/bin/fluoroct_fuzz_studio"
  mkdir -p "$work/corpus/$t" "$work/crashes/$t" "$seeds/$t"
  local limits=(-timeout=10 -rss_limit_mb=6144 -malloc_limit_mb=2048 -print_final_stats=1 -runs="$runs")
  ((seconds > 0)) && limits+=(-max_total_time="$seconds")
  echo "fuzz: $t for ${seconds}s (runs $runs) ..."
  local scratch=/dev/shm/fluoroct-fuzz-$$-$t  # the loaders' RAM folder; a crash leaves it behind, so it is removed here
  [[ -d /dev/shm ]] || scratch="$tmp/scratch-$t"
  set +e
  QT_QPA_PLATFORM=offscreen FCT_FUZZ_TARGET=$t FCT_FUZZ_SCRATCH=$scratch nice -n 19 "$program" "${limits[@]}" \
    -artifact_prefix="$work/crashes/$t/" "$work/corpus/$t" "$seeds/$t" >"$log" 2>&1
  status=$?
  set -e
  rm -rf "$scratch"
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  kept=$(find "$work/crashes/$t" -type f | wc -l)
  printf '%-18s %12s executions  %3d crash inputs kept  (exit %d, log %s)\n' "$t" "${executions:-?}" "$kept" \
    "$status" "$log" >"$tmp/summary-$t"
  ((status == 0 && kept == 0)) || touch "$tmp/crashed"
}
running=0
for t in "${targets[@]}"; do
  if ((running >= jobs)); then
    wait -n || true
    running=$((running - 1))
  fi
  run_target "$t" &
  running=$((running + 1))
done
wait
echo
echo "fuzz: $(date -u '+%Y-%m-%d %H:%M UTC'), ${seconds}s per target (runs $runs), $jobs at once, $(nproc) cores"
for t in "${targets[@]}"; do cat "$tmp/summary-$t"; done
crashed=0
[[ -e $tmp/crashed ]] && crashed=1
((crashed == 0)) || echo "fuzz: crash inputs are in $work/crashes/<target>/"
exit "$crashed"

#!/usr/bin/env bash
# Builds FluoroCT (installing any missing Debian packages) and runs every test with CTest.
#   bash scripts/test.sh              the normal Release build in build/, every test; with CI=true (what CI runs)
#                                     then also the sanitizer suite's quick tests (--sanitize -LE slow)
#   bash scripts/test.sh --sanitize   the Core, Logic and Apps tests built with AddressSanitizer +
#                                     UndefinedBehaviorSanitizer in build-asan/; any sanitizer report fails its test
# Other arguments go to ctest (e.g. -LE slow).
# Widget tests run with QT_QPA_PLATFORM=offscreen; the whole run is inside xvfb-run for tests that render.
set -euo pipefail
FCT_SCRIPTS="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
FCT_ASAN_BUILD="$(dirname "$FCT_SCRIPTS")/build-asan"
sanitize=0 ctest_args=()
for arg in "$@"; do
  case "$arg" in
    --sanitize) sanitize=1 ;;
    *) ctest_args+=("$arg") ;;
  esac
done

# Runs ctest in $FCT_BUILD with the given arguments, then the caller's.
fct_run_ctest() {
  cd "$FCT_BUILD"
  xvfb-run -a -s "-screen 0 1600x1000x24" ctest --output-on-failure -j "${FCT_JOBS:-$(nproc)}" "$@" \
    ${ctest_args[@]+"${ctest_args[@]}"}
}

if ((!sanitize)); then
  source "$FCT_SCRIPTS/setup.sh"
  fct_run_ctest
  # CI (CI=true) also runs the sanitizer suite without its slow tests (docs/robustness.md "Sanitizers").
  if [[ ${CI:-} == true ]]; then
    bash "$FCT_SCRIPTS/test.sh" --sanitize -LE slow ${ctest_args[@]+"${ctest_args[@]}"}
  fi
  exit 0
fi
# The sanitizer suite: the Core, Logic and Apps tests (the CLI included); the Studio's Qt/VTK stack is left out
# (docs/robustness.md).
# -O1: a quicker instrumented build than -O2 (docs/robustness.md); -g1 gives file:line in the reports. Reports abort
# the test (no recover).
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
FCT_BUILD_DIR="$FCT_ASAN_BUILD"
FCT_CMAKE_ARGS=(-DCMAKE_CXX_FLAGS_RELEASE="-O1 -g1 -DNDEBUG" -DCMAKE_CXX_FLAGS="$flags"
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined")
FCT_BUILD_TARGETS=(fluoroct fluoroct_core_tests fluoroct_logic_tests fluoroct_cli_tests)
# Also in force at build time: the test programs are run to list their tests. The leak suppressions name
# third-party libraries only (Testing/Sanitizers/lsan.supp says why).
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$(dirname "$FCT_SCRIPTS")/Testing/Sanitizers/lsan.supp:print_suppressions=0"
source "$FCT_SCRIPTS/setup.sh"
fct_run_ctest -L '^(Core|Logic|Apps)$'

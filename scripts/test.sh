#!/usr/bin/env bash
# Builds FluoroCT (installing any missing Debian packages) and runs every test with CTest, twice: the normal Release
# build in build/, then the same suite built with AddressSanitizer + UndefinedBehaviorSanitizer in build-asan/.
#   bash scripts/test.sh                 both suites (what CI runs)
#   bash scripts/test.sh --no-sanitize   the normal suite only
#   bash scripts/test.sh --sanitize      the sanitizer suite only (Core, Logic and Apps tests)
# Other arguments go to ctest, for both suites (e.g. -LE slow). Any sanitizer report fails its test.
# Widget tests run with QT_QPA_PLATFORM=offscreen; the whole run is inside xvfb-run for tests that render.
set -euo pipefail
FCT_SCRIPTS="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
FCT_ASAN_BUILD="$(dirname "$FCT_SCRIPTS")/build-asan"
normal=1 sanitize=1 ctest_args=()
for arg in "$@"; do
  case "$arg" in
    --sanitize) normal=0 ;;
    --no-sanitize) sanitize=0 ;;
    *) ctest_args+=("$arg") ;;
  esac
done

# Runs ctest in $FCT_BUILD with the given arguments, then the caller's.
fct_run_ctest() {
  cd "$FCT_BUILD"
  xvfb-run -a -s "-screen 0 1600x1000x24" ctest --output-on-failure -j "${FCT_JOBS:-$(nproc)}" "$@" \
    ${ctest_args[@]+"${ctest_args[@]}"}
}

if ((normal)); then
  source "$FCT_SCRIPTS/setup.sh"
  fct_run_ctest
fi
# The sanitizer suite: the Core, Logic and Apps tests (the CLI included); the Studio's Qt/VTK stack is left out to keep
# CI short (docs/robustness.md).
if ((sanitize)); then
  # -O2 keeps the registration tests quick; -g1 gives file:line in the reports. Reports abort the test (no recover).
  flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
  FCT_BUILD_DIR="$FCT_ASAN_BUILD"
  FCT_CMAKE_ARGS=(-DCMAKE_CXX_FLAGS_RELEASE="-O2 -g1 -DNDEBUG" -DCMAKE_CXX_FLAGS="$flags"
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined")
  FCT_BUILD_TARGETS=(fluoroct fluoroct_core_tests fluoroct_logic_tests fluoroct_cli_tests)
  # Also in force at build time: the test programs are run to list their tests. The leak suppressions name
  # third-party libraries only (Testing/Sanitizers/lsan.supp says why).
  export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:strict_string_checks=1"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  export LSAN_OPTIONS="suppressions=$(dirname "$FCT_SCRIPTS")/Testing/Sanitizers/lsan.supp:print_suppressions=0"
  if ((normal)); then
    FCT_BUILD="$FCT_ASAN_BUILD"
    fct_build
  else
    source "$FCT_SCRIPTS/setup.sh"
  fi
  fct_run_ctest -L '^(Core|Logic|Apps)$'
fi

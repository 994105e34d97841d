#!/usr/bin/env bash
# Builds FluoroCT (installing any missing Debian packages) and runs every test with CTest.
# Widget tests run with QT_QPA_PLATFORM=offscreen; the whole run is inside xvfb-run for tests that render.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
cd "$FCT_BUILD"
xvfb-run -a -s "-screen 0 1600x1000x24" ctest --output-on-failure -j "${FCT_JOBS:-$(nproc)}" "$@"

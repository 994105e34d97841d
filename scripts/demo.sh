#!/usr/bin/env bash
# Builds FluoroCT (installing any missing Debian packages) and runs the richest end-to-end job on the built-in
# phantom case, which needs no data.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
BIN="$FCT_BUILD/bin"
OUT="${FCT_DEMO_DIR:-$FCT_BUILD/demo}"
mkdir -p "$OUT"
"$BIN/fluoroct" --version

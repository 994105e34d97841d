#!/usr/bin/env bash
# Builds and runs the DRR benchmark: plastimatch `drr -i exact` vs our Siddon, trilinear ray caster and Transgraph
# on the pelvis CT and the head phantom (800x600 detector, SID 1500 mm, SAD 1000 mm), 1 and 2 threads.
# Usage: Testing/Benchmarks/run_drr_benchmark.sh [--threads N] [--repeats N] [--transgraph-rays N] [--no-plastimatch]
# Environment: BUILD_DIR (default build), FLUOROCT_DATA_DIR (default ../shared/data beside the source tree).
set -euo pipefail
SOURCE_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$SOURCE_DIR/build}"
if [[ ! -f "$BUILD_DIR/CMakeCache.txt" ]]; then
  cmake -S "$SOURCE_DIR" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
cmake --build "$BUILD_DIR" -j2 --target DrrBenchmark
exec "$BUILD_DIR/bin/DrrBenchmark" "$@"

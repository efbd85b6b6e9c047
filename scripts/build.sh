#!/usr/bin/env bash
# Configures and builds the Release tree in build/ (shared by run.sh and test.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSHADEL_BENCH=ON >/dev/null
cmake --build build -j"$jobs"

#!/usr/bin/env bash
# The main job: install, build, render builtin:default with decoupled shading, lit by the
# built-in sky, to out/default.png + out/default.json.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
mkdir -p out
./build/src/app/shadel render --scene builtin:default --mode decoupled --size 1280x720 --frames 3 \
    --out out/default.png --stats out/default.json --passes "$@"
echo "wrote out/default.png and out/default.json"

#!/usr/bin/env bash
# Sets up, builds psysc, checks a sample (default: the thesis's fireworks) and runs it.
#   bash scripts/demo.sh [samples/NAME.psys]
set -euo pipefail
cd "$(dirname "$0")/.."
sample=${1:-samples/fireworks.psys}

bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build build -j "$(nproc)" --target psysc

build/tools/psysc/psysc check --time "$sample"
# 10 seconds at 60 frames a second: a line per frame with the live objects of each type,
# every drawn point of every 60th frame in build/demo.csv.
build/tools/psysc/psysc run "$sample" --frames 600 --dump build/demo.csv --dump-every 60

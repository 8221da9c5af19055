#!/usr/bin/env bash
# Sets up, builds psysc and runs it on a sample (default: the thesis's fireworks).
#   bash scripts/demo.sh [samples/NAME.psys]
set -euo pipefail
cd "$(dirname "$0")/.."
sample=${1:-samples/fireworks.psys}

bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build build -j "$(nproc)" --target psysc

build/tools/psysc/psysc check --time "$sample"
build/tools/psysc/psysc --emit=ast "$sample"

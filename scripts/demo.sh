#!/usr/bin/env bash
# Sets up (scripts/setup.sh run: only what building and running psysc and psys-view
# needs), builds those two and shows a sample (default: the thesis's fireworks) in the
# viewer: in a window where there is a display, else rendered offscreen to build/demo.png.
# Prints how long each stage took (scripts/stages.sh).
#   bash scripts/demo.sh [samples/NAME.psys]
set -euo pipefail
cd "$(dirname "$0")/.."
sample=${1:-samples/fireworks.psys}
source scripts/stages.sh

stage "set-up" bash scripts/setup.sh run
# Without the tests and benchmarks, which need packages only the test profile installs.
stage "configure" cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBUILD_TESTING=OFF -DPSYS_BENCH=OFF \
  -DPSYS_DEBUG_INFO=lines -DPSYS_UNITY=ON
stage "build psysc and psys-view" cmake --build build -j "$(nproc)" --target psysc psys-view

stage "check" build/tools/psysc/psysc check --time "$sample"
if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
  trap - EXIT
  stages_report
  # Edit and save the file while it runs: the viewer reloads it. `psys-view --help` lists the keys.
  exec build/tools/viewer/psys-view "$sample"
fi
# No display (a server, CI): 10 seconds of it, drawn offscreen with the panel, as a PNG.
stage "run headless" build/tools/viewer/psys-view --headless "$sample" --frames 600 --fit --ui --screenshot build/demo.png --log
echo "no display: the sample after 10 s is in $(pwd)/build/demo.png (psys-view --help for the window's keys)"

#!/usr/bin/env bash
# Sets up, builds and shows a sample (default: the thesis's fireworks) in the viewer: in a
# window where there is a display, else rendered offscreen to build/demo.png.
#   bash scripts/demo.sh [samples/NAME.psys]
set -euo pipefail
cd "$(dirname "$0")/.."
sample=${1:-samples/fireworks.psys}

bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build build -j "$(nproc)" --target psysc psys-view

build/tools/psysc/psysc check --time "$sample"
if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
  # Edit and save the file while it runs: the viewer reloads it. `psys-view --help` lists the keys.
  exec build/tools/viewer/psys-view "$sample"
fi
# No display (a server, CI): 10 seconds of it, drawn offscreen with the panel, as a PNG.
build/tools/viewer/psys-view --headless "$sample" --frames 600 --fit --ui --screenshot build/demo.png --log
echo "no display: the sample after 10 s is in $(pwd)/build/demo.png (psys-view --help for the window's keys)"

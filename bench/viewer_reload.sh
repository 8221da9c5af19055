#!/usr/bin/env bash
# The hitch of a hot reload in psys-view: the slowest frame from a save to the frame that
# shows the new system, against a normal frame (frames paced at --fps, as a display's
# refresh paces a window). Each backend runs a sample headless for a while and the file
# is saved with a new constant three times (new kernels each time: nothing cached).
#
#   bash bench/viewer_reload.sh [BUILD] [SAMPLE] [FPS]     (build, samples/fire.psys, 60)
#
# Prints psys-view's own "reload hitch" lines (--log) for each backend.
set -euo pipefail
build=${1:-build}
sample=${2:-$(dirname "$0")/../samples/fire.psys}
fps=${3:-60}
view="$build/tools/viewer/psys-view"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PSYS_GL_CACHE=0  # compiled programs are not kept between runs: every reload compiles
for backend in llvm glsl; do
  cp "$sample" "$work/a.psys"
  (
    for edit in 1 2 3; do
      sleep 2
      # A comment changes no kernel: a new constant does (the first decimal number outside
      # a comment, with digits appended: 0.3 becomes 0.300123).
      python3 -c 'import re, sys; t = open(sys.argv[1]).read(); m = re.search(r"^(?!\s*//).*?\d+\.\d+", t, re.M); print(t[:m.end()] + "00" + sys.argv[2] + t[m.end():], end="")' \
        "$sample" "$edit$RANDOM" > "$work/a.tmp"
      mv "$work/a.tmp" "$work/a.psys"
    done
  ) &
  echo "== $backend, $(basename "$sample"), paced at $fps fps"
  "$view" --headless "$work/a.psys" --backend "$backend" --frames $((fps * 9)) --fps "$fps" --log --size 640x360 |
    grep -E "reload hitch|reload:|reload failed" || true
  wait
done

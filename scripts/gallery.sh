#!/usr/bin/env bash
# The gallery (docs/gallery.md): one picture per sample, each the headless viewer's frame
# 600 at the default seed and a fixed step, the camera fitted to what is alive, written
# to docs/gallery/NAME.png. A sample that waits for its host (triggers) gets a script of
# what a person would do (docs/gallery/NAME.script). Regenerate every picture:
#
#   scripts/gallery.sh [build-dir]        (default: build)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
view=$build/tools/viewer/psys-view
[ -x "$view" ] || { echo "gallery: no $view (build first)" >&2; exit 1; }
frames=600
for sample in "$here"/samples/*.psys; do
  name=$(basename "$sample" .psys)
  args=(--headless "$sample" --frames "$frames" --fit --size 960x540 --screenshot "$here/docs/gallery/$name.png")
  [ -f "$here/docs/gallery/$name.script" ] && args+=(--script "$here/docs/gallery/$name.script")
  "$view" "${args[@]}" > /dev/null
  echo "docs/gallery/$name.png"
done

#!/usr/bin/env bash
# Save → first frame of the new system, for every sample, as the viewer does it: each
# sample runs headless at 60 frames a second from a copy; the copy is saved three times (a
# new object type appended — its kernels compiled —, the original back — everything
# cached —, and every `age` made `age * 1.0001` — most kernels compiled again), and the
# viewer's log says how long after each save the first frame of the new system came out
# (on the interpreter meanwhile where the JIT took longer than 50 ms). docs/viewer.md has
# a run.
#   bash scripts/reload_latency.sh [build]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
view="$build/tools/viewer/psys-view"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
printf "| sample | an object added (ms) | back to the original (ms) | every age changed (ms) |\n|---|---:|---:|---:|\n"
for sample in samples/*.psys; do
  name=$(basename "$sample" .psys)
  cp "$sample" "$work/$name.psys"
  "$view" --headless "$work/$name.psys" --frames 300 --fps 60 --log --no-grid > "$work/$name.log" 2>&1 &
  pid=$!
  sleep 1.2
  cp "$sample" "$work/$name.tmp" && printf '\nobject psys_edit_probe { point(vec3(0, 1, 0), white, 1); }\n' >> "$work/$name.tmp"
  mv "$work/$name.tmp" "$work/$name.psys"
  sleep 1.2
  cp "$sample" "$work/$name.tmp" && mv "$work/$name.tmp" "$work/$name.psys"
  sleep 1.2
  sed 's/\bage\b/(age * 1.0001)/g' "$sample" > "$work/$name.tmp" && mv "$work/$name.tmp" "$work/$name.psys"
  wait "$pid"
  times=$(grep -o 'first frame of the new system [0-9.]* ms' "$work/$name.log" | grep -o '[0-9.]* ms' | tr -d ' ms' | tr '\n' ' ')
  read -r added back changed <<< "$times"
  printf "| %s | %s | %s | %s |\n" "$name" "${added:-?}" "${back:-?}" "${changed:-?}"
done

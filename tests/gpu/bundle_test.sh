#!/usr/bin/env bash
# The GPU bundle (scripts/gpu-bundle.sh) from this build, unpacked into an empty
# directory and run from there with a bare environment: every library but the C
# library's comes from the bundle, it is at most 60 MiB (packed at xz -1, below), and its
# tests and the program generator pass there (a few of them here: the whole suite runs as
# gpu.* already, the generator as progen.*).
#   bundle_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Packed at xz's level 1 (a fifth of level 6's time): within 60 MiB there, within it at 6.
PSYS_BUNDLE_BUILD=$build PSYS_BUNDLE_XZ_LEVEL=1 bash "$root/scripts/gpu-bundle.sh" "$tmp/bundle.tar.xz"
size=$(stat -c %s "$tmp/bundle.tar.xz")
[ "$size" -le $((60 * 1024 * 1024)) ] || { echo "bundle_test: the bundle is $size bytes, over 60 MiB" >&2; exit 1; }
mkdir "$tmp/empty"
tar -C "$tmp/empty" -xJf "$tmp/bundle.tar.xz"
top=$tmp/empty/psys-gpu
for b in "$top"/bin/*; do
  [ -f "$b" ] || continue
  outside=$(ldd "$b" | awk '$3 ~ /^\// {print $3}' | grep -v "^$top/bin/lib/" |
            grep -Ev '/(libc|libm|libdl|libpthread|librt)\.so' || true)
  [ -z "$outside" ] || { echo "bundle_test: $(basename "$b") loads from outside the bundle: $outside" >&2; exit 1; }
done
cd "$tmp/empty"
env -i PATH=/usr/bin:/bin HOME="$tmp" ./psys-gpu/run.sh tests -tc="every operation*,IEEE*" | tee "$tmp/out"
grep -q "^GL: " "$tmp/out"
grep -q "run.sh tests: passed, strict mode passed" "$tmp/out"
env -i PATH=/usr/bin:/bin HOME="$tmp" ./psys-gpu/run.sh progen --seeds 1:2 | tee "$tmp/progen"
grep -q "^2 cases in .*: 2 the same on every backend" "$tmp/progen"

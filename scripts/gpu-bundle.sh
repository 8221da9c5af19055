#!/usr/bin/env bash
# Packs what a GPU machine needs to run psys's GPU tests, benchmark and samples when it
# has a GL driver but none of this build: one tarball, unpacked anywhere, run with
# `run.sh tests|bench|samples` (docs/gpu.md, "On a GPU machine").
#
#   bash scripts/gpu-bundle.sh OUT.tar.xz
#
# Builds Release in build-release (reusing it where it exists; PSYS_BUNDLE_BUILD names
# another build directory) and carries psys_gpu_tests, psys_gpu_bench, psysc, psys-view,
# psys-progen (the program generator: tools/progen),
# the samples, the test programs and the standard library (share/psys/std, found beside
# bin/ as an installed psys finds it), and every shared library they load but the C
# library's own — libstdc++ and the vendor-neutral GL dispatch (libglvnd's libEGL,
# libOpenGL, libGLX, libGL, libGLdispatch, which libepoxy opens at run time) included;
# a vendor's driver never: the machine's own is found through libglvnd.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -eq 1 ] || { echo "usage: bash scripts/gpu-bundle.sh OUT.tar.xz" >&2; exit 2; }
out=$(realpath -m "$1")
build=${PSYS_BUNDLE_BUILD:-$root/build-release}

if [ ! -f "$build/build.ninja" ]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPSYS_WERROR=ON
fi
cmake --build "$build" -j "$(nproc)" --target psys_gpu_tests psys_gpu_bench psysc psys-view psys-progen

stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
top=$stage/psys-gpu
mkdir -p "$top/bin/lib" "$top/samples" "$top/programs/generated" "$top/share/psys/std"
binaries=(tests/gpu/psys_gpu_tests bench/psys_gpu_bench tools/psysc/psysc tools/viewer/psys-view tools/progen/psys-progen)
for b in "${binaries[@]}"; do
  install -m 755 "$build/$b" "$top/bin/"
done

# The libraries: what ldd resolves for each binary, less the C library's own (the machine
# has its own, matched to its kernel), plus the GL dispatch libepoxy and GLFW dlopen.
is_libc() {
  case "$(basename "$1")" in
    ld-linux*|libc.so*|libm.so*|libdl.so*|libpthread.so*|librt.so*|libresolv.so*|linux-vdso*) return 0 ;;
  esac
  return 1
}
libs=()
for b in "${binaries[@]}"; do
  while read -r path; do
    [ -n "$path" ] && ! is_libc "$path" && libs+=("$path")
  done < <(ldd "$build/$b" | awk '$3 ~ /^\// {print $3}')
done
for name in libEGL.so.1 libOpenGL.so.0 libGLdispatch.so.0 libGLX.so.0 libGL.so.1; do
  path=$(ldconfig -p | awk -v n="$name" '$1 == n && $0 ~ /x86-64/ {print $NF; exit}')
  [ -n "$path" ] || { echo "gpu-bundle: $name not found (libglvnd: libegl1, libopengl0, libgl1)" >&2; exit 1; }
  libs+=("$path")
done
printf '%s\n' "${libs[@]}" | sort -u | while read -r path; do
  cp -L "$path" "$top/bin/lib/$(basename "$path")"
done
# Binaries find their libraries beside them, wherever the bundle is unpacked.
for b in "$top"/bin/*; do
  [ -f "$b" ] || continue
  strip --strip-debug "$b"
  patchelf --set-rpath '$ORIGIN/lib' "$b"
done
for l in "$top"/bin/lib/*; do
  chmod u+w "$l"
  strip --strip-debug "$l" 2>/dev/null || true
  patchelf --set-rpath '$ORIGIN' "$l"
done

cp "$root"/samples/*.psys "$top/samples/"
cp "$root"/library/std/*.psys "$top/share/psys/std/"
cp "$root"/tests/programs/*.psys "$top/programs/"
cp "$root"/tests/programs/generated/*.psys "$top/programs/generated/" 2>/dev/null || true
install -m 755 "$root/scripts/gpu-bundle-run.sh" "$top/run.sh"
git -C "$root" rev-parse HEAD > "$top/COMMIT" 2>/dev/null || echo unknown > "$top/COMMIT"

mkdir -p "$(dirname "$out")"
# PSYS_BUNDLE_XZ_LEVEL: xz's level (6 by default: 47 MB in 80 s here; the bundle test packs
# at 1, 57 MB in 16 s — if that fits the 60 MiB a device takes, 6 does).
tar -C "$stage" -cf - psys-gpu | xz -T0 -"${PSYS_BUNDLE_XZ_LEVEL:-6}" > "$out"
echo "gpu-bundle: $out ($(du -h "$out" | cut -f1)): unpack anywhere, then psys-gpu/run.sh tests|bench|samples"

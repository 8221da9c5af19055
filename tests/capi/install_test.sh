#!/usr/bin/env bash
# The installed package as a host uses it: `cmake --install` into an empty prefix; the
# library's soname and its exports (the C API's symbols and nothing else); the examples
# built against the prefix with find_package(psys) and with pkg-config, run on a sample
# and on a program that imports the standard library (found beside the installed library);
# the GLFW example in a window where a display can be made (xvfb-run).
#   install_test.sh BUILD_DIR SOURCE_DIR
# It works outside the build tree (where the tools would find the tree's own library), in
# a directory removed when it passes.
set -euo pipefail
build=$(realpath "$1") src=$(realpath "$2")
work=$(mktemp -d /tmp/psys-installed.XXXXXX)
trap 'status=$?; if [ $status = 0 ]; then rm -rf "$work"; else echo "(kept: $work)"; fi' EXIT
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
# Exported: the global symbols (upper-case types, and u: unique), less the version node (A).
exported() { nm -D --defined-only "$1" | awk '$2 != "A" && $2 ~ /^[A-Zu]$/ {print $3}'; }
for name in psys psys_runtime; do
  real=$(readlink -f "$prefix/lib/lib$name.so")
  soname=$(objdump -p "$real" | awk '/SONAME/ {print $2}')
  [ "$soname" = "lib$name.so.0.3" ] || { echo "soname: $soname, not lib$name.so.0.3"; exit 1; }
  others=$(exported "$real" | grep -v '^psys_' || true)
  if [ -n "$others" ]; then
    echo "lib$name.so exports more than the C API:"; echo "$others" | head -20; exit 1
  fi
  echo "lib$name.so: $(stat -c %s "$real") bytes, $(exported "$real" | wc -l) symbols exported, all psys_*"
done
if ldd "$prefix/lib/libpsys_runtime.so" | grep -i llvm; then echo "libpsys_runtime loads LLVM"; exit 1; fi
for f in include/psys/psys.h lib/cmake/psys/psysConfig.cmake lib/pkgconfig/psys.pc lib/pkgconfig/psys-runtime.pc \
         lib/pkgconfig/psys-runtime-static.pc lib/libpsys_runtime.a share/psys/std bin/psysc; do
  [ -e "$prefix/$f" ] || { echo "not installed: $f"; exit 1; }
done

# find_package(psys)
cmake -S "$src/examples" -B "$work/examples" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" > "$work/examples.log"
cmake --build "$work/examples" >> "$work/examples.log"
"$work/examples/minimal" "$src/samples/fountain.psys" | tee "$work/minimal.out"
grep -q "drops drawn: [1-9]" "$work/minimal.out"

# The ahead-of-time example: built by the package's psysc, linked with libpsys_runtime
# alone: no LLVM in the process.
"$work/examples/aot_host" 6000 | tee "$work/aot.out"
grep -q "drops alive after 4 s" "$work/aot.out"
if ldd "$work/examples/aot_host" | grep -i "llvm\|libpsys.so"; then echo "the AOT host loads the compiler"; exit 1; fi
# … and linked statically (psys::runtime_static, and pkg-config's psys-runtime-static):
# no libpsys library at run time.
"$work/examples/aot_host_static" 6000 | tee "$work/aot-static.out"
cmp "$work/aot.out" "$work/aot-static.out"
"$prefix/bin/psysc" build "$src/samples/fountain.psys" -o "$work/fountain" > /dev/null
static=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs psys-runtime-static)
cc -std=c99 -Wall -Wextra -Wpedantic -Werror -I"$work" -o "$work/aot-pc-static" \
  "$src/examples/c/aot_host.c" "$work/fountain.a" $static
for host in "$work/examples/aot_host_static" "$work/aot-pc-static"; do
  if ldd "$host" | grep -i "llvm\|libpsys"; then echo "$host loads a psys library: not static"; exit 1; fi
done
"$work/aot-pc-static" 6000 | grep -q "drops alive after 4 s"

# pkg-config as docs/embedding.md says it (the .pc file is relocatable: the prefix is where
# it lies; it carries an rpath, so the binary finds the library with no LD_LIBRARY_PATH)
flags=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs psys)
cc -std=c99 -Wall -Wextra -Wpedantic -Werror -o "$work/minimal-pc" "$src/examples/c/minimal.c" $flags
cat > "$work/library.psys" <<'PSYS'
import "std/shapes.psys";
object bead(p: vec3) {
    point(p, white, 1);
}
object source { emit bead(on_sphere(2)) count 50; }
spawn source;
PSYS
"$work/minimal-pc" "$work/library.psys" | tee "$work/library.out"
grep -q "beads drawn: 50" "$work/library.out"

# The Python package, where the build made it: from the prefix, finding libpsys beside it.
pydir=$(find "$prefix/lib" -maxdepth 3 -type d -name dist-packages | head -1)
if [ -n "$pydir" ] && [ -e "$pydir/psys/__init__.py" ]; then
  PYTHONPATH="$pydir" /usr/bin/python3 -c "
import psys, sys
s = psys.compile(sys.argv[1])
s.step(1 / 60, steps=60)
print('python from the prefix:', psys.version, len(s.points('drop')['id']), 'drops')" "$src/samples/fountain.psys" \
    | tee "$work/python.out"
  grep -q "python from the prefix: .* [1-9][0-9]* drops" "$work/python.out"
fi

# In a window, where one can be made: the llvm backend's columns uploaded, the glsl
# backend's GL buffers drawn as they are. Each picture must show the fountain's drops.
if command -v xvfb-run > /dev/null; then
  for backend in llvm glsl; do
    xvfb-run -a -s "-screen 0 1280x720x24" "$work/examples/glfw_host" "$src/samples/fountain.psys" \
      --backend $backend --frames 90 --png "$work/glfw_$backend.png"
    lit=$(/usr/bin/python3 -c "import matplotlib.image as m, sys; p = m.imread(sys.argv[1]); print(int((p[:, :, :3].max(axis=2) > 0.3).sum()))" \
          "$work/glfw_$backend.png")
    echo "glfw_host on $backend: $lit pixels lit"
    [ "$lit" -gt 1000 ] || { echo "glfw_host drew too little on $backend"; exit 1; }
  done
  # 200 instances of two effects on turning rings, each played again as it finishes.
  xvfb-run -a -s "-screen 0 1280x720x24" "$work/examples/glfw_host" "$src/examples/effects/burst.psys" \
    "$src/examples/effects/halo.psys" --play 100 --frames 150 --eye 0,6,10 --at 0,2.5,0 --png "$work/instances.png" \
    | tee "$work/instances.out"
  [ "$(grep -c ', 100 instances playing' "$work/instances.out")" = 2 ] || { echo "glfw_host --play: not 2 × 100"; exit 1; }
  lit=$(/usr/bin/python3 -c "import matplotlib.image as m, sys; p = m.imread(sys.argv[1]); print(int((p[:, :, :3].max(axis=2) > 0.3).sum()))" \
        "$work/instances.png")
  echo "glfw_host --play 100: $lit pixels lit"
  [ "$lit" -gt 2000 ] || { echo "glfw_host --play drew too little"; exit 1; }
fi
echo "installed package: ok"

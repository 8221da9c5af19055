#!/usr/bin/env bash
# Sets up, builds (Release) and installs psys under PREFIX: psysc, libpsys (compiling and
# running) and libpsys_runtime (ahead-of-time builds alone), include/psys/psys.h, the CMake
# package and pkg-config files, the standard library, and the Python package `psys`
# (into PREFIX/lib/python3.X/dist-packages, which Debian's Python searches for /usr/local;
# for /usr, lib/python3/dist-packages). docs/embedding.md.
#   bash scripts/install.sh [PREFIX]          # /usr/local by default (as root, or through sudo)
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=${1:-/usr/local}

bash scripts/setup.sh
cmake -S . -B build-install -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF -DCMAKE_INSTALL_PREFIX="$prefix"
cmake --build build-install -j "$(nproc)"
SUDO=""
mkdir -p "$prefix" 2>/dev/null || true
[ -w "$prefix" ] || SUDO="sudo"
$SUDO cmake --install build-install
# The libraries where the dynamic linker looks (a prefix of its own needs LD_LIBRARY_PATH,
# or an rpath: the CMake package's targets carry one).
if [ "$(id -u)" -eq 0 ] || [ -n "$SUDO" ]; then $SUDO ldconfig || true; fi
echo "installed psys $(grep -m1 -o 'VERSION [0-9.]*' CMakeLists.txt | cut -d' ' -f2) under $prefix"

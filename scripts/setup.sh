#!/usr/bin/env bash
# Installs every Debian package psys needs to build, test and run.
# Non-interactive and idempotent: running it again changes nothing.
set -euo pipefail

packages=(
  cmake ninja-build pkg-config g++ git
  antlr4 libantlr4-runtime-dev
  llvm-19-dev libzstd-dev
  libglm-dev libglfw3-dev libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libimgui-dev
  doctest-dev libcli11-dev libfmt-dev nlohmann-json3-dev libstb-dev libtbb-dev
  glslang-tools xvfb xauth libbenchmark-dev python3-matplotlib
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"

#!/usr/bin/env bash
# Installs every Debian package psys needs to build, test and run, and the editor
# extension's npm packages (editor-support/vscode, versions pinned in package-lock.json).
# Non-interactive and idempotent: running it again changes nothing.
set -euo pipefail

packages=(
  cmake ninja-build pkg-config g++ git
  antlr4 libantlr4-runtime-dev
  llvm-19-dev libzstd-dev
  libglm-dev libglfw3-dev libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libimgui-dev
  mesa-vulkan-drivers libvulkan1
  doctest-dev libcli11-dev libfmt-dev nlohmann-json3-dev libstb-dev libtbb-dev
  glslang-tools xvfb xauth patchelf xz-utils libbenchmark-dev python3-matplotlib vim
  clang-19 libclang-rt-19-dev
  ffmpeg fonts-dejavu-core
  python3-dev python3-pybind11 python3-numpy python3-pytest
  neovim
  xterm x11-apps  # scripts/editor-screenshot.sh: Neovim in an xterm, captured with xwd
)
# Node.js 20 and npm (the editor extension's tests and package) come with the machine;
# where they do not, Debian's are installed.
command -v node >/dev/null && command -v npm >/dev/null || packages+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
else
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# npm ci installs exactly what package-lock.json pins; it runs again only when the lock changed.
vscode="$(cd "$(dirname "$0")/.." && pwd)/editor-support/vscode"
if [ ! -f "$vscode/node_modules/.package-lock.json" ] || [ "$vscode/package-lock.json" -nt "$vscode/node_modules/.package-lock.json" ]; then
  major=$(node -p 'process.versions.node.split(".")[0]')
  [ "$major" -ge 20 ] || echo "setup: warning: Node.js $major is older than 20, which @vscode/vsce needs to package the extension" >&2
  (cd "$vscode" && npm ci --no-audit --no-fund --loglevel=error)
else
  echo "setup: editor-support/vscode/node_modules up to date"
fi

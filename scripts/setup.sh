#!/usr/bin/env bash
# Installs the Debian packages (and, for the editor, the npm packages) one of psys's jobs
# needs. Non-interactive and idempotent: running it again changes nothing.
#   bash scripts/setup.sh run      # build and run psysc and psys-view (scripts/demo.sh)
#   bash scripts/setup.sh editor   # the editor extension's npm packages (editor-support/vscode,
#                                  # versions pinned in package-lock.json), and Node.js where missing
#   bash scripts/setup.sh test     # everything the tests use: run + editor + the rest (scripts/test.sh)
# With no profile: test.
set -euo pipefail

profile=${1:-test}
case $profile in run | editor | test) ;; *) echo "usage: bash scripts/setup.sh [run|editor|test]" >&2; exit 2 ;; esac

# Building and running psysc and psys-view, headless included (EGL on Mesa); ccache and mold
# make rebuilds and links fast (CMakeLists.txt uses them where they are installed).
run_packages=(
  cmake ninja-build pkg-config g++ git ccache mold
  antlr4 libantlr4-runtime-dev
  uuid-dev  # the ANTLR runtime's CMake package links -luuid; Debian's -dev package does not pull it in
  llvm-19-dev libzstd-dev
  libglm-dev libglfw3-dev libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libimgui-dev
  libcli11-dev libfmt-dev nlohmann-json3-dev libstb-dev libtbb-dev
  fonts-dejavu-core  # the viewer's panel font
)
# The editor extension's tests and package: Node.js 20 and npm come with the machine; where
# they do not, Debian's are installed.
editor_packages=()
command -v node >/dev/null && command -v npm >/dev/null || editor_packages+=(nodejs npm)
# What only the tests, benchmarks and fuzzers use.
test_packages=(
  doctest-dev libbenchmark-dev
  mesa-vulkan-drivers libvulkan1  # zink over lavapipe: the GPU tests' second GL
  glslang-tools xvfb xauth
  patchelf xz-utils               # the GPU bundle (scripts/gpu-bundle.sh)
  python3-matplotlib
  clang-19 libclang-rt-19-dev     # the sanitizer build (scripts/test.sh) and the fuzzers (scripts/fuzz.sh)
  ffmpeg                          # the viewer's video recording
  python3-dev python3-pybind11 python3-numpy python3-pytest
  vim neovim                      # the editor tests' real clients
  xterm x11-apps                  # scripts/editor-screenshot.sh: Neovim in an xterm, captured with xwd
)

packages=("${run_packages[@]}")
case $profile in
  editor) packages=("${editor_packages[@]}") ;;
  test) packages+=("${editor_packages[@]}" "${test_packages[@]}") ;;
esac

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup ($profile): all ${#packages[@]} packages already installed"
else
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

[ "$profile" = run ] && exit 0

# npm ci installs exactly what package-lock.json pins; it runs again only when the lock changed.
vscode="$(cd "$(dirname "$0")/.." && pwd)/editor-support/vscode"
if [ ! -f "$vscode/node_modules/.package-lock.json" ] || [ "$vscode/package-lock.json" -nt "$vscode/node_modules/.package-lock.json" ]; then
  major=$(node -p 'process.versions.node.split(".")[0]')
  [ "$major" -ge 20 ] || echo "setup: warning: Node.js $major is older than 20, which @vscode/vsce needs to package the extension" >&2
  (cd "$vscode" && npm ci --no-audit --no-fund --loglevel=error)
else
  echo "setup: editor-support/vscode/node_modules up to date"
fi

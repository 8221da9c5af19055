#!/usr/bin/env bash
# Sets up, builds and runs every test: a release build with warnings as errors, then the
# same tests under AddressSanitizer and UndefinedBehaviorSanitizer.
#   PSYS_SKIP_SANITIZE=1 bash scripts/test.sh   # only the first build
#   PSYS_SKIP_FUZZ=1 bash scripts/test.sh       # without the brief fuzzing (scripts/fuzz.sh)
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/setup.sh
jobs=$(nproc)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPSYS_WERROR=ON
cmake --build build -j "$jobs"
ctest --test-dir build -j "$jobs" --output-on-failure

if [ "${PSYS_SKIP_SANITIZE:-0}" != 1 ]; then
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DPSYS_WERROR=ON -DPSYS_SANITIZE=ON
  cmake --build build-asan -j "$jobs"
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan -j "$jobs" --output-on-failure
fi

# The fuzz targets keep building and, run briefly (the same inputs every time), keep
# finding nothing.
if [ "${PSYS_SKIP_FUZZ:-0}" != 1 ]; then
  FUZZ_RUNS=1 bash scripts/fuzz.sh
fi

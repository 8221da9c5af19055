#!/usr/bin/env bash
# Sets up, builds and runs every test: a release build with warnings as errors, then the
# same tests under AddressSanitizer and UndefinedBehaviorSanitizer, then the fuzzers
# briefly. At the end (passed or not) it prints how long each stage took and the slowest
# tests of each ctest run (scripts/stages.sh; also in build/stages.txt).
#   PSYS_SKIP_SANITIZE=1 bash scripts/test.sh   # only the first build
#   PSYS_SKIP_FUZZ=1 bash scripts/test.sh       # without the brief fuzzing (scripts/fuzz.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/stages.sh

stage "set-up" bash scripts/setup.sh test
jobs=$(nproc)

stage "release: configure" cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPSYS_WERROR=ON \
  -DBUILD_TESTING=ON -DPSYS_BENCH=ON -DPSYS_DEBUG_INFO=lines
stage "release: build" cmake --build build -j "$jobs"
stage_tests "release" build
stage "release: ctest" ctest --test-dir build -j "$jobs" --output-on-failure

# LeakSanitizer's stop-the-world tracer can itself crash at exit ("Tracer caught signal 11",
# a sanitizer run-time bug with threads holding dynamic TLS, here the GL driver's) after the
# test passed. When every failure is that crash, those tests run once more; any other
# failure stands.
sanitized_ctest() {
  export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1
  local log=build-asan/Testing/asan-run.log failed crashes
  ctest --test-dir build-asan -j "$jobs" --output-on-failure --output-log "$log" && return 0
  failed=$(wc -l < build-asan/Testing/Temporary/LastTestsFailed.log)
  crashes=$(grep -c 'LeakSanitizer has encountered a fatal error' "$log" || true)
  [ "$failed" -gt 0 ] && [ "$failed" = "$crashes" ] || return 1
  echo "== $failed test(s) failed only in LeakSanitizer's tracer: running them again"
  ctest --test-dir build-asan --rerun-failed --output-on-failure
}

# Under the sanitizers, the tests without the benchmarks: the release stage runs each once
# (bench.*), and their loops are the library's, which the tests run here.
if [ "${PSYS_SKIP_SANITIZE:-0}" != 1 ]; then
  stage "asan: configure" cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DPSYS_WERROR=ON -DPSYS_SANITIZE=ON \
    -DBUILD_TESTING=ON -DPSYS_BENCH=OFF -DPSYS_DEBUG_INFO=lines
  stage "asan: build" cmake --build build-asan -j "$jobs"
  stage_tests "asan" build-asan
  stage "asan: ctest" sanitized_ctest
fi

# The fuzz targets keep building and, run briefly (the same inputs every time), keep
# finding nothing.
if [ "${PSYS_SKIP_FUZZ:-0}" != 1 ]; then
  stage "fuzz: build and run" env FUZZ_RUNS=1 bash scripts/fuzz.sh
fi

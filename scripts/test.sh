#!/usr/bin/env bash
# Sets up, builds and runs every test: a release build with warnings as errors and a build
# under AddressSanitizer and UndefinedBehaviorSanitizer; each test then runs once, in the
# stage where it proves the most (release_selection, below); then the fuzzers briefly. At
# the end (passed or not) it prints how long each stage took and the slowest tests of
# each ctest run (scripts/stages.sh; also in build/stages.txt).
#   PSYS_SKIP_SANITIZE=1 bash scripts/test.sh   # only the release build, every test in it
#   PSYS_SKIP_FUZZ=1 bash scripts/test.sh       # without the brief fuzzing (scripts/fuzz.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/stages.sh

stage "set-up" bash scripts/setup.sh test
jobs=$(nproc)

sanitize=1
[ "${PSYS_SKIP_SANITIZE:-0}" = 1 ] && sanitize=0

stage "release: configure" cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPSYS_WERROR=ON \
  -DBUILD_TESTING=ON -DPSYS_BENCH=ON -DPSYS_DEBUG_INFO=lines -DPSYS_UNITY=ON
stage "release: build" cmake --build build -j "$jobs"

# Under the sanitizers, the tests without the benchmarks: the release stage runs each once
# (bench.*), and their loops are the library's, which the tests run here. Built with
# Clang: the release build has GCC's warnings, this one Clang's, and Clang compiles the
# instrumented code in about two thirds of GCC's time (rt's batch: 44 s against 69).
if [ $sanitize = 1 ]; then
  # (the C compiler from CC: C is enabled late, for the C API's test, and LLVM's CMake
  # package checks a C source as soon as CMAKE_C_COMPILER is set)
  stage "asan: configure" env CC=clang-19 cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DPSYS_WERROR=ON \
    -DPSYS_SANITIZE=ON -DCMAKE_CXX_COMPILER=clang++-19 -DBUILD_TESTING=ON -DPSYS_BENCH=OFF -DPSYS_DEBUG_INFO=lines -DPSYS_UNITY=ON
  stage "asan: build" cmake --build build-asan -j "$jobs"
fi

# The names of the tests a build registers (`ctest -N`), one a line.
test_names() { ctest --test-dir "$1" -N | sed -n 's/^ *Test *#[0-9]*: //p'; }

# The doctest cases in the suite `long` (tests/run_length.h), as CTest names them: those of
# build/tests/.../psys_NAME_tests are NAME.CASE (psys_unit_tests: CASE).
long_tests() {
  local exe prefix
  find build/tests -name 'psys_*_tests' -type f -executable | sort | while read -r exe; do
    prefix=$(basename "$exe" | sed 's/^psys_\(.*\)_tests$/\1./; s/^unit\.$//')
    "$exe" --test-suite=long --list-test-cases < /dev/null | grep -v -e '^\[doctest\]' -e '^=*$' | sed "s/^/$prefix/"
  done
}

# Each test runs once: under the sanitizers (the same code on the same inputs, with memory
# errors and undefined behaviour caught), unless the release build is where it proves
# more — then in the release stage: the tests only the release build registers (the
# benchmarks, the GPU suite in strict mode and on zink, the GPU bundle, the AOT archives,
# the installed C API, Python), and the doctest cases in the suite `long`, which run longer
# there (tests/run_length.h). Without the sanitizer stage, the release stage runs every test.
release_selection() {
  local file=$PWD/build/Testing/release-stage.txt  # (ctest reads a relative one from --test-dir)
  mkdir -p build/Testing
  if [ $sanitize = 0 ]; then echo "0,0,0" > "$file"; echo "$file"; return; fi
  sort <(test_names build-asan) > build/Testing/sanitized-names.txt
  { comm -23 <(test_names build | sort) build/Testing/sanitized-names.txt; long_tests; } |
    sort -u > build/Testing/release-names.txt
  # ctest -I takes the tests' numbers: 0,0,0 then the list
  ctest --test-dir build -N | sed -n 's/^ *Test *#\([0-9]*\): \(.*\)$/\1\t\2/p' |
    awk -F'\t' 'NR == FNR { keep[$0] = 1; next } ($2 in keep) { printf ",%s", $1 }' build/Testing/release-names.txt - |
    sed 's/^/0,0,0/' > "$file"
  echo "$file"
}

stage_tests "release" build
stage "release: ctest" ctest --test-dir build -j "$jobs" --output-on-failure -I "$(release_selection)"

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
  # (ctest rewrites its cost data on a rerun and mangles the names with spaces in it: the
  # stage timer reads the whole run's, kept aside)
  local costs=build-asan/Testing/Temporary/CTestCostData.txt
  cp "$costs" "$costs.run"
  ctest --test-dir build-asan --rerun-failed --output-on-failure || return 1
  mv "$costs.run" "$costs"
}

if [ $sanitize = 1 ]; then
  stage_tests "asan" build-asan
  stage "asan: ctest" sanitized_ctest
fi

# The fuzz targets keep building and, run briefly (the same inputs every time), keep
# finding nothing.
if [ "${PSYS_SKIP_FUZZ:-0}" != 1 ]; then
  stage "fuzz: build and run" env FUZZ_RUNS=1 bash scripts/fuzz.sh
fi

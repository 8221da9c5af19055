#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang-19 in build-fuzz and runs each for
# SECONDS (default 60), from a corpus seeded with the samples, tests/errors/,
# tests/programs/ and (for the IR target) the samples' IR. What they find goes to
# build-fuzz/crashes/; the corpora grow in build-fuzz/corpus/.
#   bash scripts/fuzz.sh [SECONDS]     # CI runs it briefly; README names the long run
#   FUZZ_TARGETS="fuzz_frontend" bash scripts/fuzz.sh 1800   # some of them (all three are built)
#   FUZZ_RUNS=1 bash scripts/fuzz.sh       # CI: a fixed number of inputs per target from seed 1
#                                          # in a fresh corpus, so a run is the same every time
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
bash scripts/setup.sh test >/dev/null

cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++-19 -DPSYS_FUZZ=ON -DPSYS_WERROR=OFF -DBUILD_TESTING=OFF -DPSYS_BENCH=OFF \
  -DPSYS_DEBUG_INFO=lines -DPSYS_UNITY=ON >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target fuzz_frontend fuzz_ir fuzz_pipeline

seeds=build-fuzz/seeds
rm -rf "$seeds" && mkdir -p "$seeds/psys" "$seeds/ir" build-fuzz/crashes
cp samples/*.psys tests/errors/*.psys tests/programs/*.psys "$seeds/psys/"
if [ -x build/tools/psysc/psysc ]; then
  for f in samples/*.psys tests/programs/*.psys; do
    build/tools/psysc/psysc --emit=ir --no-optimize "$f" > "$seeds/ir/$(basename "$f" .psys).ir" 2>/dev/null || true
    build/tools/psysc/psysc --emit=ir "$f" > "$seeds/ir/$(basename "$f" .psys).opt.ir" 2>/dev/null || true
  done
fi

# Inputs per target for FUZZ_RUNS: about half a minute each on 2 cores (the seed corpus
# read first, then mutations of it; docs/performance.md, "Build and test times").
runs_for() { case $1 in fuzz_frontend) echo 6000 ;; fuzz_ir) echo 25000 ;; *) echo 3000 ;; esac; }

status=0
for target in ${FUZZ_TARGETS:-fuzz_frontend fuzz_ir fuzz_pipeline}; do
  corpus=build-fuzz/corpus/$target
  limit=(-max_total_time="$seconds")
  if [ -n "${FUZZ_RUNS:-}" ]; then
    corpus=build-fuzz/corpus-ci/$target
    rm -rf "$corpus"
    limit=(-runs="$(runs_for "$target")" -seed=1)
  fi
  mkdir -p "$corpus"
  seed=$seeds/psys
  [ "$target" = fuzz_ir ] && seed=$seeds/ir
  echo "fuzz: $target ${limit[*]}"
  if ! build-fuzz/fuzz/$target "$corpus" "$seed" -dict=fuzz/psys.dict "${limit[@]}" -timeout=20 \
       -rss_limit_mb=4096 -artifact_prefix="build-fuzz/crashes/$target-" -print_final_stats=1 2>build-fuzz/$target.log; then
    status=1
    echo "fuzz: $target found a failure: build-fuzz/crashes/, build-fuzz/$target.log" >&2
  fi
  grep -E "^stat::(number_of_executed_units|average_exec_per_sec|peak_rss_mb)" build-fuzz/$target.log || true
done
exit $status

#!/usr/bin/env bash
# An ahead-of-time build of a sample, linked into a C host with libpsys_runtime alone,
# draws bit for bit what the JIT draws in the same maths (300 frames, every 10th
# compared); the host needs no LLVM (ldd), the object refers to no LLVM symbol and
# defines one visible symbol, NAME_aot (readelf).
# With BACKEND glsl, the build's IR runs on the GPU (llvmpipe in CI) and draws what
# `psysc run --backend glsl` draws.
# FLAGS: more for psysc build (`--cpu x86-64-v2,native --no-glsl`).
#   aot_test.sh PSYSC BUILD_DIR SOURCE_DIR SAMPLE.psys MATH [BACKEND [FLAGS]]
set -euo pipefail
psysc=$1 build=$2 src=$3 sample=$4 math=$5 backend=${6:-llvm} flags=${7:-}
work=$(mktemp -d /tmp/psys-aot.XXXXXX)
trap 'status=$?; if [ $status = 0 ]; then rm -rf "$work"; else echo "(kept: $work)"; fi' EXIT
name=$(basename "$sample" .psys)

# shellcheck disable=SC2086 # (FLAGS are words)
"$psysc" build "$sample" -o "$work/$name" --math "$math" $flags
cc -std=c99 -Wall -Wextra -Wpedantic -Werror -I"$src/include" -include "$work/$name.h" -DAOT_SYMBOL="${name}_aot" \
   -o "$work/host" "$src/tests/aot/aot_dump.c" "$work/$name.a" -L"$build/capi" -lpsys_runtime -lmvec -lm \
   -Wl,-rpath,"$build/capi"
if ldd "$work/host" | grep -i llvm; then echo "the host of an AOT build loads LLVM"; exit 1; fi
if nm -u "$work/$name.a" | grep -i llvm; then echo "the AOT object refers to LLVM"; exit 1; fi
# Its one visible symbol is the table: kernels are local (two builds share no name), or
# hidden where too large for the table's object (large.o).
globals=$(readelf -sW "$work/$name.a" | awk '$5 == "GLOBAL" && $6 == "DEFAULT" && $7 != "UND" { print $8 }')
if [ "$globals" != "${name}_aot" ]; then echo "the archive defines more than ${name}_aot:"; echo "$globals"; exit 1; fi

"$work/host" 300 10 "$backend" > "$work/aot.csv"
"$psysc" run "$sample" --backend "$backend" --math "$math" --frames 300 --dump-every 10 --dump "$work/jit.csv" \
  --quiet > /dev/null
python3 "$src/tests/aot/compare_dumps.py" "$work/jit.csv" "$work/aot.csv"

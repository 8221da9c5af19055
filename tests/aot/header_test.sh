#!/usr/bin/env bash
# psysc build's header for PROGRAM compiles as C99 and as C++17, pedantic, warnings as
# errors: every name the language accepts (a keyword of C or C++ included) gives a header
# a host can include.
#   header_test.sh PSYSC SOURCE_DIR PROGRAM
set -euo pipefail
psysc=$1 src=$2 program=$3
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$psysc" build "$program" -o "$out/effect"
cc -std=c99 -pedantic -Wall -Wextra -Werror -fsyntax-only -I"$src/include" -x c "$out/effect.h"
c++ -std=c++17 -pedantic -Wall -Wextra -Werror -fsyntax-only -I"$src/include" -x c++ "$out/effect.h"
echo "the header compiles as C99 and C++17"

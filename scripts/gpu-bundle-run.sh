#!/usr/bin/env bash
# run.sh of a GPU bundle (scripts/gpu-bundle.sh): psys's GPU tests, benchmark and samples
# on this machine's GL, from wherever the bundle was unpacked.
#   ./run.sh tests [doctest options]    the GPU test suite, then again in strict mode
#   ./run.sh bench [bench options]      psys_gpu_bench (default: 1e5 1e6 1e7 particles); with
#                                       --samples: every sample at 1e5 and 1e7 live objects, what
#                                       a step costs the host (dispatches, waits, bytes)
#   ./run.sh samples                    every sample on the GPU and on the interpreter: the same counts
#   ./run.sh progen [options]           generated programs on every backend against the interpreter,
#                                       on this GL and in strict mode (default: --minutes 5; the kept
#                                       cases first); what differs is kept in ./progen-found
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=$here/bin
# What libepoxy and GLFW open at run time (the GL dispatch) is found beside the binaries too.
export LD_LIBRARY_PATH="$bin/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export PSYS_SAMPLES_DIR="$here/samples" PSYS_PROGRAMS_DIR="$here/programs"
cd "$here"

echo "psys $(cat "$here/COMMIT")"
if ! info=$("$bin/psysc" run --backend glsl --timing --quiet --frames 1 "$here/samples/fountain.psys" 2>&1); then
  echo "$info"
  echo "run.sh: no OpenGL 4.5 to run on (above: why)" >&2
  exit 2
fi
echo "GL: $(echo "$info" | sed -n 's/^compiled [0-9]* kernels in [0-9.]* ms (\(.*\), [a-z]* math.*)$/\1/p')"

what=${1:-}
shift || true
case "$what" in
  tests)
    "$bin/psys_gpu_tests" "$@"; plain=$?
    echo "== strict mode (a full barrier and glFinish after every GPU write)"
    PSYS_GPU_STRICT=1 "$bin/psys_gpu_tests" "$@"; strict=$?
    echo "run.sh tests: $([ $plain = 0 ] && echo passed || echo FAILED), strict mode $([ $strict = 0 ] && echo passed || echo FAILED)"
    [ $plain = 0 ] && [ $strict = 0 ]
    ;;
  bench)
    [ $# -gt 0 ] || set -- --particles 1e5 1e6 1e7
    "$bin/psys_gpu_bench" "$@"
    ;;
  samples)
    failed=0
    for s in "$here"/samples/*.psys; do
      gpu=$("$bin/psysc" run --backend glsl --frames 600 --quiet "$s" 2>&1 | grep -E '^  [a-z_]+ +live')
      cpu=$("$bin/psysc" run --backend interp --frames 600 --quiet "$s" 2>&1 | grep -E '^  [a-z_]+ +live')
      if [ "$gpu" = "$cpu" ] && [ -n "$gpu" ]; then
        echo "ok      $(basename "$s")"
      else
        echo "DIFFERS $(basename "$s")"; echo "  GPU:"; echo "$gpu"; echo "  interpreter:"; echo "$cpu"
        failed=1
      fi
    done
    "$bin/psys-view" --headless "$here/samples/fireworks.psys" --backend glsl --frames 420 --fit \
      --screenshot "$here/fireworks.png" > /dev/null && echo "the viewer drew $here/fireworks.png"
    exit $failed
    ;;
  progen)
    [ $# -gt 0 ] || set -- --minutes 5
    kept=()
    for f in "$here"/programs/generated/*.psys; do
      case $f in *.edit.psys) ;; *) [ -f "$f" ] && kept+=("$f") ;; esac
    done
    failed=0
    for mode in "" strict; do
      echo "== the program generator${mode:+ in strict mode}"
      if [ ${#kept[@]} -gt 0 ]; then
        PSYS_GPU_STRICT=${mode:+1} "$bin/psys-progen" --quiet --replay "${kept[@]}" || failed=1
      fi
      PSYS_GPU_STRICT=${mode:+1} "$bin/psys-progen" --quiet --out "$here/progen-found" "$@" || failed=1
    done
    exit $failed
    ;;
  *)
    echo "usage: run.sh tests|bench|samples|progen [options]" >&2
    exit 2
    ;;
esac

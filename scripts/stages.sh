# The stage timer of scripts/test.sh and scripts/demo.sh (sourced): `stage NAME COMMAND…`
# runs COMMAND and records how long it took; when the script ends, passed or not, a table
# of every stage and the slowest tests of each ctest run (`stage_tests NAME BUILD_DIR`
# records where their times are) is printed, and written to build/stages.txt.

stages_names=()
stages_seconds=()
stages_results=()
stages_test_dirs=()
stages_start=$EPOCHREALTIME

# b − a, seconds
stages_since() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }
stages_minutes() { awk -v s="$1" 'BEGIN { printf "%.1f", s / 60 }'; }

# Runs "$@" as the stage NAME; returns its status (so `set -e` stops the script there).
stage() {
  local name=$1 t0 rc=0
  shift
  t0=$EPOCHREALTIME
  echo "== $name: $*"
  "$@" || rc=$?
  stages_names+=("$name")
  stages_seconds+=("$(stages_since "$t0" "$EPOCHREALTIME")")
  stages_results+=("$([ $rc = 0 ] && echo ok || echo "failed ($rc)")")
  return $rc
}

# After a ctest run in BUILD_DIR: its slowest tests go into the report under NAME.
stage_tests() { stages_test_dirs+=("$1=$2"); }

stages_report() {
  local total i
  total=$(stages_since "$stages_start" "$EPOCHREALTIME")
  {
    echo
    echo "== stage times"
    printf '%-28s %9s %7s  %s\n' stage seconds minutes result
    for i in "${!stages_names[@]}"; do
      printf '%-28s %9.1f %7.1f  %s\n' "${stages_names[$i]}" "${stages_seconds[$i]}" \
        "$(stages_minutes "${stages_seconds[$i]}")" "${stages_results[$i]}"
    done
    printf '%-28s %9.1f %7.1f\n' total "$total" "$(stages_minutes "$total")"
    # ctest keeps each test's time in Testing/Temporary/CTestCostData.txt ("NAME RUNS SECONDS",
    # a run's own time where it ran once).
    for entry in "${stages_test_dirs[@]}"; do
      local name=${entry%%=*} dir=${entry#*=} data
      data=$dir/Testing/Temporary/CTestCostData.txt
      [ -f "$data" ] || continue
      echo
      echo "== the 15 slowest tests of $name (seconds; $(sed '/^---/q' "$data" | grep -vc '^---') tests, $(
        sed '/^---/q' "$data" | awk '$3 ~ /^[0-9.]+$/ { s += $3 } END { printf "%.0f", s }') s in all)"
      sed '/^---/q' "$data" | awk '$3 ~ /^[0-9.]+$/ { printf "%9.1f  %s\n", $3, $1 }' | sort -rn | head -15
    done
  } | tee build/stages.txt
}
mkdir -p build
trap stages_report EXIT

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
    # ctest keeps each test's time in Testing/Temporary/CTestCostData.txt ("NAME RUNS SECONDS"
    # a line, the name with spaces in it; a run's own time where it ran once), then "---".
    for entry in "${stages_test_dirs[@]+"${stages_test_dirs[@]}"}"; do
      local name=${entry%%=*} dir=${entry#*=} data
      data=$dir/Testing/Temporary/CTestCostData.txt
      [ -f "$data" ] || continue
      sed '/^---/q' "$data" | grep -v '^---' |
        awk '{ cost = $NF; name = $1; for (i = 2; i <= NF - 2; ++i) name = name " " $i; printf "%9.1f  %s\n", cost, name }' |
        sort -rn > "$dir/Testing/test-times.txt"
      echo
      echo "== the 15 slowest tests of $name (seconds; $(wc -l < "$dir/Testing/test-times.txt") tests, $(
        awk '{ s += $1 } END { printf "%.0f", s }' "$dir/Testing/test-times.txt") s in all)"
      head -15 "$dir/Testing/test-times.txt"
    done
  } | tee build/stages.txt
}
mkdir -p build
trap stages_report EXIT

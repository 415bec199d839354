#!/usr/bin/env bash
# The test command (and .ci/run): installs what is missing, builds in Release and runs every
# test (GoogleTest, Python and pvbatch suites) through ctest; then builds the Core, filter,
# reliability and guarded-reading GoogleTests and the fuzz targets with AddressSanitizer +
# UndefinedBehaviorSanitizer (clang) and runs them, the fuzz targets replaying their seed corpus
# and every regression input once. Nothing here is random or open-ended, so the same commit
# gets the same verdict every time; exploratory fuzzing is ./Tools/fuzz.sh.
#
# Ends with each stage's count and time, and a line "N passed, M failed" over both stages (a
# build that fails counts as one failure). Exits non-zero when anything failed.
#
# Build directories: MLR_BUILD_DIR (default build), MLR_ASAN_BUILD_DIR (build-asan).
# MLR_SKIP_SANITIZERS=1 runs the Release stage only.
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${MLR_BUILD_DIR:-$root/build}"
asan="${MLR_ASAN_BUILD_DIR:-$root/build-asan}"

summaries=()
total_passed=0
total_failed=0

# run_ctest NAME BUILD_DIR [ctest arguments]: runs ctest with its output shown and kept, and
# records the stage's closing summary.
run_ctest() {
  local name=$1 directory=$2
  shift 2
  local log="$directory/ctest-$name.log" start=$SECONDS
  ctest --test-dir "$directory" --output-on-failure -j 2 --timeout 900 --no-tests=error "$@" \
    2>&1 | tee "$log"
  local summary passed failed total
  summary=$(grep -E '^[0-9]+% tests passed, [0-9]+ tests? failed out of [0-9]+' "$log" | tail -n 1)
  if [ -n "$summary" ]; then
    failed=$(sed -E 's/.* ([0-9]+) tests? failed out of.*/\1/' <<<"$summary")
    total=$(sed -E 's/.*out of ([0-9]+).*/\1/' <<<"$summary")
    passed=$((total - failed))
  else
    passed=0
    failed=1 # ctest itself failed (no tests found, bad build tree)
  fi
  record "$name" "$passed" "$failed" $((SECONDS - start))
  if [ "$failed" -gt 0 ]; then
    summaries+=("  failed in $name:")
    while read -r line; do summaries+=("    $line"); done \
      < <(sed -n '/^The following tests FAILED:/,/^Errors while running/p' "$log" | grep -E '^\s+[0-9]+ - ')
  fi
}

record() { # NAME PASSED FAILED SECONDS
  summaries+=("$(printf '%-16s %4d passed, %d failed, %d s' "$1:" "$2" "$3" "$4")")
  total_passed=$((total_passed + $2))
  total_failed=$((total_failed + $3))
}

# --- Release: every test ------------------------------------------------------------------
start=$SECONDS
if MLR_BUILD_DIR="$build" "$root/Tools/build.sh"; then
  summaries+=("$(printf '%-16s %d s' "Release build:" $((SECONDS - start)))")
  run_ctest Release "$build"
else
  record "Release build" 0 1 $((SECONDS - start))
fi

# --- Sanitizers: Core, filter, reliability and guarded-reading tests, fuzz replays --------
# Only our code is instrumented (VTK, ParaView, Embree, TBB are Debian's builds); the
# executables carry their sanitizer options (Testing/Reliability/SanitizerDefaults.cxx).
if [ "${MLR_SKIP_SANITIZERS:-0}" != 1 ]; then
  start=$SECONDS
  sanitizer_targets=(mlrCoreTests mlrFilterTests mlrReliabilityTests mlrGuardedReadTests
    mlr-fuzz-solve mlr-fuzz-readers)
  if CC=clang CXX=clang++ cmake -S "$root" -B "$asan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
       -DPython3_EXECUTABLE=/usr/bin/python3 -DMLR_SANITIZE=address,undefined >/dev/null &&
     cmake --build "$asan" -j 2 --target "${sanitizer_targets[@]}"; then
    summaries+=("$(printf '%-16s %d s' "Sanitizer build:" $((SECONDS - start)))")
    run_ctest Sanitizers "$asan" -L '^(Core|Filters|Reliability|Fuzz)$'
  else
    record "Sanitizer build" 0 1 $((SECONDS - start))
  fi
fi

echo
echo "=== Summary ($SECONDS s in all) ==="
printf '%s\n' "${summaries[@]}"
echo "$total_passed passed, $total_failed failed"
[ "$total_failed" -eq 0 ]

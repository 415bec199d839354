#!/usr/bin/env bash
# Installs what is missing, builds in Release and runs every test (GoogleTest, Python and
# pvbatch suites) through ctest. Then (issue 7) builds the Core, filter and reliability
# GoogleTests with AddressSanitizer + UndefinedBehaviorSanitizer (clang) and runs them, and
# builds the libFuzzer targets and runs each for a bounded time. Exits non-zero when anything
# fails: a failed test, a sanitizer report, a fuzzer crash, hang or memory over its limit.
#
# Build directories: MLR_BUILD_DIR (default build), MLR_ASAN_BUILD_DIR (build-asan),
# MLR_FUZZ_BUILD_DIR (build-fuzz). MLR_FUZZ_SECONDS (default 30) is each fuzzer's time;
# MLR_SKIP_SANITIZERS=1 runs the Release part only.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/Tools/build.sh"
build="${MLR_BUILD_DIR:-$root/build}"
status=0
ctest --test-dir "$build" --output-on-failure -j 2 --timeout 900 || status=$?
echo "Release stage: ${SECONDS} s"
stage=$SECONDS

if [ "${MLR_SKIP_SANITIZERS:-0}" = 1 ]; then
  exit "$status"
fi
failed=()
[ "$status" -eq 0 ] || failed+=("Release tests")

# --- Sanitizers: Core, filter and reliability GoogleTests and the fuzz corpus replays -------
# Only our code is instrumented (VTK, ParaView, Embree, TBB are Debian's builds); the
# executables carry their sanitizer options (Testing/Reliability/SanitizerDefaults.cxx).
asan="${MLR_ASAN_BUILD_DIR:-$root/build-asan}"
sanitizer_targets=(mlrCoreTests mlrFilterTests mlrReliabilityTests mlr-fuzz-solve mlr-fuzz-readers)
if CC=clang CXX=clang++ cmake -S "$root" -B "$asan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
     -DPython3_EXECUTABLE=/usr/bin/python3 -DMLR_SANITIZE=address,undefined >/dev/null &&
   cmake --build "$asan" -j 2 --target "${sanitizer_targets[@]}"; then
  ctest --test-dir "$asan" --output-on-failure -j 2 --timeout 900 --no-tests=error \
    -L '^(Core|Filters|Reliability|Fuzz)$' || failed+=("sanitizer tests")
else
  failed+=("sanitizer build")
fi
echo "sanitizer stage: $((SECONDS - stage)) s"
stage=$SECONDS

# --- Fuzzing: each libFuzzer target for a bounded time --------------------------------------
# New inputs go to build-fuzz/fuzz-corpus/<target>; crashes, hangs (-timeout) and memory over
# -rss_limit_mb end the run with a non-zero status and a file in build-fuzz/fuzz-artifacts.
# (mlr-fuzz-readers reads each file in a child process, as the command line does: "oom-" files
# there may come from such a child refusing a file; only the fuzzer's exit status counts.)
fuzz="${MLR_FUZZ_BUILD_DIR:-$root/build-fuzz}"
if CC=clang CXX=clang++ cmake -S "$root" -B "$fuzz" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
     -DPython3_EXECUTABLE=/usr/bin/python3 -DMLR_SANITIZE=address,undefined -DMLR_FUZZ=ON >/dev/null &&
   cmake --build "$fuzz" -j 2 --target mlr-fuzz-solve mlr-fuzz-readers; then
  for target in solve readers; do
    corpus="$fuzz/fuzz-corpus/$target"
    artifacts="$fuzz/fuzz-artifacts/$target"
    log="$fuzz/fuzz-$target.log"
    mkdir -p "$corpus" "$artifacts"
    seeds=()
    for directory in corpus regressions; do
      [ -d "$root/Testing/Fuzz/$directory/$target" ] && seeds+=("$root/Testing/Fuzz/$directory/$target")
    done
    echo "fuzzing mlr-fuzz-$target for ${MLR_FUZZ_SECONDS:-30} s (log: $log)"
    if "$fuzz/bin/mlr-fuzz-$target" -max_total_time="${MLR_FUZZ_SECONDS:-30}" \
         -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 -artifact_prefix="$artifacts/" \
         "$corpus" "${seeds[@]}" >"$log" 2>&1; then
      grep -E '^(Done|stat::number_of_executed_units|stat::peak_rss_mb)' "$log" || true
    else
      tail -n 80 "$log"
      failed+=("fuzzing mlr-fuzz-$target")
    fi
  done
else
  failed+=("fuzz build")
fi
echo "fuzzing stage: $((SECONDS - stage)) s"

if [ ${#failed[@]} -gt 0 ]; then
  printf 'FAILED: %s\n' "${failed[@]}" >&2
  [ "$status" -ne 0 ] && exit "$status"
  exit 1
fi
echo "Release, sanitizer and fuzzing stages passed"

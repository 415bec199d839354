#!/usr/bin/env bash
# Exploratory fuzzing (not part of the test command, whose verdict must not depend on chance):
#
#   ./Tools/fuzz.sh [SECONDS] [TARGET...]
#
# Builds the libFuzzer targets with AddressSanitizer + UndefinedBehaviorSanitizer (clang) in
# MLR_FUZZ_BUILD_DIR (default build-fuzz) and runs each TARGET (solve, readers; default both)
# for SECONDS (default 60), starting from Testing/Fuzz/corpus/<target> and regressions/<target>
# and keeping what it learns in build-fuzz/fuzz-corpus/<target>. A crash, a hang (over 20 s for
# one input), memory over 2 GiB or a leak ends the target's run; the input is copied to
# Testing/Fuzz/regressions/<target>/, where the test command replays it (and fails on it until
# it is fixed). Give it a name that says what it was once fixed. Exits non-zero on a finding.
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(solve readers)
case "$seconds" in
  '' | *[!0-9]*) echo "usage: $0 [SECONDS] [solve|readers]..." >&2; exit 2 ;;
esac

"$root/Tools/setup-debian.sh"
fuzz="${MLR_FUZZ_BUILD_DIR:-$root/build-fuzz}"
CC=clang CXX=clang++ cmake -S "$root" -B "$fuzz" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPython3_EXECUTABLE=/usr/bin/python3 -DMLR_SANITIZE=address,undefined -DMLR_FUZZ=ON >/dev/null ||
  exit 1
cmake --build "$fuzz" -j 2 --target "${targets[@]/#/mlr-fuzz-}" || exit 1

findings=()
for target in "${targets[@]}"; do
  corpus="$fuzz/fuzz-corpus/$target"
  artifacts="$fuzz/fuzz-artifacts/$target"
  regressions="$root/Testing/Fuzz/regressions/$target"
  log="$fuzz/fuzz-$target.log"
  mkdir -p "$corpus" "$artifacts"
  rm -f "$artifacts"/*
  seeds=()
  for directory in corpus regressions; do
    [ -d "$root/Testing/Fuzz/$directory/$target" ] && seeds+=("$root/Testing/Fuzz/$directory/$target")
  done
  echo "fuzzing mlr-fuzz-$target for $seconds s (log: $log)"
  # -timeout stays above the readers target's own limit on a reading process (4 s of wall-clock
  # time for small files), so that a reader that loops is refused, not reported.
  if "$fuzz/bin/mlr-fuzz-$target" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=20 \
       -print_final_stats=1 -artifact_prefix="$artifacts/" "$corpus" "${seeds[@]}" >"$log" 2>&1; then
    grep -E '^(Done|stat::number_of_executed_units|stat::peak_rss_mb)' "$log"
  else
    tail -n 60 "$log"
    # Only the fuzzer's own finding counts: a reading process of the readers target is a fork
    # of the fuzzer, and libFuzzer's malloc limit may leave an oom- file there when it refuses
    # a file, which the fuzzer treats as a normal outcome.
    newest=$(ls -t "$artifacts" 2>/dev/null | head -n 1)
    if [ -n "$newest" ]; then
      mkdir -p "$regressions"
      cp "$artifacts/$newest" "$regressions/$newest"
      findings+=("mlr-fuzz-$target: Testing/Fuzz/regressions/$target/$newest")
    else
      findings+=("mlr-fuzz-$target: failed without an input (see $log)")
    fi
  fi
done

if [ ${#findings[@]} -gt 0 ]; then
  printf 'FINDING: %s\n' "${findings[@]}" >&2
  exit 1
fi
echo "fuzzing found nothing in ${targets[*]} ($seconds s each)"

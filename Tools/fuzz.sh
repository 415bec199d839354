#!/usr/bin/env bash
# Exploratory fuzzing (not part of the test command, whose verdict must not depend on chance):
#
#   ./Tools/fuzz.sh [SECONDS] [TARGET...]
#
# Builds the libFuzzer targets with AddressSanitizer + UndefinedBehaviorSanitizer (clang) in
# MLR_FUZZ_BUILD_DIR (default build-fuzz) and runs each TARGET (solve, readers; default both)
# for SECONDS (default 60), starting from Testing/Fuzz/corpus/<target> and regressions/<target>
# and keeping what it learns in build-fuzz/fuzz-corpus/<target>. A TARGET readers:FORMAT (vtp
# obj ply stl vtu vtk ies ldt gltf glb epw) spends the whole time on one format: its seeds are
# the inputs whose first byte picks that format, and its corpus is fuzz-corpus/readers-FORMAT. A crash, a hang (over 20 s for
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
  '' | *[!0-9]*) echo "usage: $0 [SECONDS] [solve|readers|readers:FORMAT]..." >&2; exit 2 ;;
esac
formats=(vtp obj ply stl vtu vtk ies ldt gltf glb epw)
binaries=()
for target in "${targets[@]}"; do
  case "$target" in
    solve | readers) binaries+=("mlr-fuzz-$target") ;;
    readers:*)
      format=${target#readers:}
      [[ " ${formats[*]} " == *" $format "* ]] ||
        { echo "$0: $target: the format must be one of ${formats[*]}" >&2; exit 2; }
      binaries+=(mlr-fuzz-readers) ;;
    *) echo "usage: $0 [SECONDS] [solve|readers|readers:FORMAT]..." >&2; exit 2 ;;
  esac
done

"$root/Tools/setup-debian.sh"
fuzz="${MLR_FUZZ_BUILD_DIR:-$root/build-fuzz}"
CC=clang CXX=clang++ cmake -S "$root" -B "$fuzz" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPython3_EXECUTABLE=/usr/bin/python3 -DMLR_SANITIZE=address,undefined -DMLR_FUZZ=ON >/dev/null ||
  exit 1
cmake --build "$fuzz" -j 2 --target $(printf '%s\n' "${binaries[@]}" | sort -u) || exit 1

findings=()
for target in "${targets[@]}"; do
  binary=${target%%:*}
  name=${target/:/-}
  corpus="$fuzz/fuzz-corpus/$name"
  artifacts="$fuzz/fuzz-artifacts/$name"
  regressions="$root/Testing/Fuzz/regressions/$binary"
  log="$fuzz/fuzz-$name.log"
  mkdir -p "$corpus" "$artifacts"
  rm -f "$artifacts"/*
  seeds=()
  for directory in corpus regressions; do
    [ -d "$root/Testing/Fuzz/$directory/$binary" ] && seeds+=("$root/Testing/Fuzz/$directory/$binary")
  done
  unset MLR_FUZZ_FORMAT
  kind=
  if [ "$binary" != "$target" ]; then
    export MLR_FUZZ_FORMAT=${target#readers:}
    for k in "${!formats[@]}"; do [ "${formats[$k]}" = "$MLR_FUZZ_FORMAT" ] && kind=$k; done
    # The seeds of this format only: the first byte of an input picks its format.
    picked="$fuzz/fuzz-seeds/$name"
    rm -rf "$picked" && mkdir -p "$picked"
    for file in $(find "${seeds[@]}" -type f); do
      first=$(od -An -tu1 -N1 "$file" | tr -d ' ')
      [ -n "$first" ] && [ $((first % 11)) -eq "$kind" ] && cp "$file" "$picked/"
    done
    seeds=("$picked")
  fi
  echo "fuzzing $target for $seconds s (log: $log)"
  # -timeout stays above the readers target's own limit on a reading process (4 s of wall-clock
  # time for small files), so that a reader that loops is refused, not reported.
  if "$fuzz/bin/mlr-fuzz-$binary" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=20 \
       -print_final_stats=1 -artifact_prefix="$artifacts/" "$corpus" "${seeds[@]}" >"$log" 2>&1; then
    grep -E '^(Done|stat::number_of_executed_units|stat::peak_rss_mb)' "$log"
    grep -E '^#[0-9]+.*cov: ' "$log" | tail -n 1
  else
    tail -n 60 "$log"
    # Only the fuzzer's own finding counts: a reading process of the readers target is a fork
    # of the fuzzer, and libFuzzer's malloc limit may leave an oom- file there when it refuses
    # a file, which the fuzzer treats as a normal outcome.
    newest=$(ls -t "$artifacts" 2>/dev/null | head -n 1)
    if [ -n "$newest" ]; then
      mkdir -p "$regressions"
      if [ -n "$kind" ]; then
        # The replay has no MLR_FUZZ_FORMAT: the first byte must pick the format itself.
        { printf "\\$(printf '%03o' "$kind")"; tail -c +2 "$artifacts/$newest"; } \
          >"$regressions/$newest"
      else
        cp "$artifacts/$newest" "$regressions/$newest"
      fi
      findings+=("$target: Testing/Fuzz/regressions/$binary/$newest")
    else
      findings+=("$target: failed without an input (see $log)")
    fi
  fi
done

if [ ${#findings[@]} -gt 0 ]; then
  printf 'FINDING: %s\n' "${findings[@]}" >&2
  exit 1
fi
echo "fuzzing found nothing in ${targets[*]} ($seconds s each)"

#!/usr/bin/env bash
# Installs what is missing, builds the command line in Release and measures it end to end on
# the demo (Benchmarks/end_to_end.py): classic against full reuse, whole command and solve
# alone, and writing the series as a share of the solve, with met / not met for the targets
# (writing at most 25% of the solve). Arguments go to end_to_end.py (e.g. --repeat 5).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/Tools/build.sh" moving-light-radiosity
build="${MLR_BUILD_DIR:-$root/build}"
exec /usr/bin/python3 "$root/Benchmarks/end_to_end.py" --cli "$build/bin/moving-light-radiosity" "$@"

#!/usr/bin/env bash
# Installs what is missing, then configures and builds the Release tree in MLR_BUILD_DIR
# (default build/). Arguments, if any, are the targets to build (default: everything).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/Tools/setup-debian.sh"
build="${MLR_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
if [ $# -gt 0 ]; then
  cmake --build "$build" -j 2 --target "$@"
else
  cmake --build "$build" -j 2
fi

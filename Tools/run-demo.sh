#!/usr/bin/env bash
# Installs what is missing, builds in Release and runs the main job: the moving-light Cornell
# box, 30 light positions, written to output/cornell.pvd (+ one .vtu per frame) with one
# PNG picture per frame in output/png/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/Tools/setup-debian.sh"
build="${MLR_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build "$build" -j 2 --target moving-light-radiosity
cd "$root"
exec "$build/bin/moving-light-radiosity" "$@"

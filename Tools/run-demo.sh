#!/usr/bin/env bash
# Installs what is missing, builds in Release and runs the main job: the moving-light Cornell
# box, 30 light positions, written to output/cornell.pvd (+ one .vtu per frame) with one
# PNG picture per frame in output/png/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/Tools/build.sh" moving-light-radiosity
build="${MLR_BUILD_DIR:-$root/build}"
cd "$root"
exec "$build/bin/moving-light-radiosity" "$@"

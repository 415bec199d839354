#!/usr/bin/env bash
# Installs what is missing, builds in Release, and reproduces the paper's measurements on the
# Cornell box: output/paper/results.json, CSV tables, plots and the middle-frame pictures.
# The first run computes the reference solution (a few minutes) and caches it in
# output/paper/cache; later runs reuse it.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/Tools/build.sh"
build="${MLR_BUILD_DIR:-$root/build}"
cd "$root"
export PYTHONPATH="$build/lib/python3/dist-packages${PYTHONPATH:+:$PYTHONPATH}"
out="${1:-output/paper}"
# The middle-frame pictures need an X display: a private Xvfb, as the tests and examples use.
/usr/bin/python3 Testing/Plugin/xvfb_display.py /usr/bin/python3 Benchmarks/paper_benchmark.py --output "$out"
/usr/bin/python3 Benchmarks/plot_paper.py "$out/results.json"

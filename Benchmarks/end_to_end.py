#!/usr/bin/python3
"""End to end: the command line on the demo, as a user runs it.

Runs moving-light-radiosity on the built-in Cornell box (30 light positions, the defaults of
Tools/run-demo.sh: 600,000 paths per frame, about 3,000 patches) with --reuse none (classic)
and --reuse both (full reuse), each writing the .pvd + .vtu series and --stats, and prints in
one run:

- the wall time of each whole command (process start to exit) and the speed-up of full reuse
  over classic, against the target of at least 6 times;
- the solve alone (remeshing + solving, from --stats) of each, and the solver's speed-up;
- the writing of the series (secondsWriting) as a share of the full-reuse solve, against the
  target of at most 25%.

The pictures of the default run (--png) are not part of it: any option turns them off, and
the targets are about the series. Each command runs --repeat times, alternating the modes, and
the median of each figure is reported (the machine may be shared). Timing only: nothing here
is a test. Tools/run-end-to-end-benchmark.sh builds the command line and runs this.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
WRITING_TARGET = 0.25  # of the full-reuse solve
SPEEDUP_TARGET = 6.0   # full reuse over classic, whole command


def default_cli():
    build = os.environ.get("MLR_BUILD_DIR", os.path.join(ROOT, "build"))
    return os.path.join(build, "bin", "moving-light-radiosity")


def run_once(cli, mode, directory, extra):
    output = os.path.join(directory, mode)
    shutil.rmtree(output, ignore_errors=True)
    stats_path = os.path.join(output, "stats.json")
    command = [cli, "--reuse", mode, "--output", os.path.join(output, "cornell.pvd"),
               "--stats", stats_path] + extra
    start = time.monotonic()
    result = subprocess.run(command, capture_output=True, text=True)
    wall = time.monotonic() - start
    if result.returncode != 0:
        sys.exit(f"{' '.join(command)} failed ({result.returncode}):\n{result.stderr}")
    with open(stats_path) as f:
        stats = json.load(f)
    timing = stats["timing"]
    size = sum(os.path.getsize(os.path.join(output, name)) for name in os.listdir(output)
               if name.endswith(".vtu"))
    return {
        "wall": wall,
        "solve": timing["secondsRemeshing"] + timing["secondsSolving"],
        "writing": timing["secondsWriting"],
        "reading": timing["secondsReading"],
        "frames": stats["statistics"]["Frames"],
        "patches": stats["statistics"]["Patches"],
        "elements": stats["statistics"]["Elements"],
        "megabytes": size / 1e6,
    }


def median_of(runs):
    return {key: statistics.median(run[key] for run in runs) for key in runs[0]}


def verdict(met):
    return "met" if met else "not met"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cli", default=default_cli(),
                        help="the moving-light-radiosity executable (default: $MLR_BUILD_DIR "
                             "or build/, bin/moving-light-radiosity)")
    parser.add_argument("--repeat", type=int, default=3,
                        help="runs of each mode; medians are reported (default 3)")
    parser.add_argument("--json", help="also write the figures to this JSON file")
    parser.add_argument("extra", nargs="*",
                        help="more options for both commands after --, e.g. -- --threads 2")
    args = parser.parse_args()
    if not os.access(args.cli, os.X_OK):
        parser.error(f"no executable {args.cli}: build it (Tools/build.sh moving-light-radiosity)"
                     " or give --cli")
    if args.repeat < 1:
        parser.error("--repeat needs at least 1")

    runs = {"none": [], "both": []}
    with tempfile.TemporaryDirectory(prefix="mlr-end-to-end-") as directory:
        for repeat in range(args.repeat):
            for mode in ("none", "both"):
                runs[mode].append(run_once(args.cli, mode, directory, args.extra))
                print(f"  run {repeat + 1}/{args.repeat} --reuse {mode}: "
                      f"{runs[mode][-1]['wall']:.2f} s", file=sys.stderr)
    classic, reuse = median_of(runs["none"]), median_of(runs["both"])

    speedup = classic["wall"] / reuse["wall"]
    solver_speedup = classic["solve"] / reuse["solve"]
    share = reuse["writing"] / reuse["solve"]
    print(f"End to end on the demo: built-in Cornell box, {reuse['frames']:.0f} frames, "
          f"{reuse['patches']:.0f} patches ({reuse['elements']:.0f} elements), "
          f"{os.cpu_count()} cores, median of {args.repeat} runs each")
    print(f"{'':24}{'classic':>10}{'full reuse':>12}")
    print(f"{'command, wall':24}{classic['wall']:>9.2f}s{reuse['wall']:>11.2f}s")
    print(f"{'solve (remesh + solve)':24}{classic['solve']:>9.2f}s{reuse['solve']:>11.2f}s")
    print(f"{'writing the series':24}{classic['writing']:>9.2f}s{reuse['writing']:>11.2f}s")
    print(f"{'reading the inputs':24}{classic['reading']:>9.3f}s{reuse['reading']:>11.3f}s")
    print(f"series: {reuse['megabytes']:.1f} MB of .vtu")
    print(f"speed-up of full reuse, whole command: {speedup:.1f}x (solve alone "
          f"{solver_speedup:.1f}x); target >= {SPEEDUP_TARGET:.0f}x: "
          f"{verdict(speedup >= SPEEDUP_TARGET)}")
    print(f"writing / full-reuse solve: {100 * share:.0f}%; target <= "
          f"{100 * WRITING_TARGET:.0f}%: {verdict(share <= WRITING_TARGET)}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"classic": classic, "fullReuse": reuse, "runs": runs,
                       "speedup": speedup, "solverSpeedup": solver_speedup,
                       "writingShare": share,
                       "speedupTargetMet": speedup >= SPEEDUP_TARGET,
                       "writingTargetMet": share <= WRITING_TARGET}, f, indent=2)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Runs one parallel test: the serial reference in plain pvbatch, then the case on R
ranks under mpiexec (pvbatch --symmetric), each bounded by a timeout, and compares what every
rank wrote (pvbatch_parallel.py). Exits non-zero with one line per failed check.

    run_parallel.py --case whole|split|time|abort|bad --ranks R --mpiexec M --pvbatch P \
        --plugin MovingLightRadiosity.so --work DIR

whole: the union of the ranks' outputs is the serial output bit for bit, cell by cell, and
       rank 0 holds it all (the input was whole on rank 0), its Sensors too (also in split).
split: the Scene is spread by RedistributeDataSet; every rank outputs cells, lying on its own
       piece of the scene; the union, sorted by cell, equals serial in every array, and the
       total power too.
time:  five time requests and no new solve on any rank; a new Seed solves once more.
abort: rank 0 aborts mid-solve: every rank reports the abort and outputs nothing, and the
       next request solves on every rank.
bad:   rank 1's piece lacks Reflectance: every rank reports an error naming it; rank 1 alone
       over its memory limit: every rank reports the limit. No rank hangs (the timeout).
"""
import argparse
import glob
import os
import signal
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "pvbatch_parallel.py")
TIMEOUT = 240


def run(command, what):
    """Runs `command` in its own process group, killing the group on timeout."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True, start_new_session=True)
    try:
        output, _ = process.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        sys.exit(f"{what}: no answer within {TIMEOUT} s (a rank hangs?): {' '.join(command)}")
    if process.returncode != 0:
        sys.exit(f"{what} exited with {process.returncode}:\n{output[-4000:]}")
    return output


def load(prefix):
    files = sorted(glob.glob(prefix + ".rank*.npz"), key=lambda f: int(f.split(".rank")[1][:-4]))
    return [dict(np.load(f, allow_pickle=False)) for f in files]


class Checks:
    def __init__(self):
        self.failures = []

    def check(self, condition, message):
        if not condition:
            self.failures.append(message)

    def finish(self, name):
        if self.failures:
            print(f"{name}: {len(self.failures)} failed checks:")
            for f in self.failures:
                print("  " + f)
            sys.exit(1)
        print(f"{name}: all checks passed")


def cell_order(corners):
    """An order of cells by their sorted corner coordinates (a cell's identity)."""
    keys = np.sort(corners.reshape(len(corners), 3, 3).round(12), axis=1).reshape(len(corners), 9)
    return np.lexsort(keys.T[::-1])


def union(ranks, prefix, kind):
    """The arrays of output `kind` (e or p) of every rank, concatenated in rank order."""
    names = set()
    for r in ranks:
        names.update(k for k in r if k.startswith(f"{prefix}{kind}_") and k != f"{prefix}{kind}_cells")
    joined = {}
    for name in names:
        parts = [r[name] for r in ranks if name in r]
        joined[name[len(prefix) + len(kind) + 1:]] = np.concatenate(parts)
    return joined


def compare(checks, reference, ranks, prefix, kind, ordered):
    """Every array of the union of the ranks' outputs against the serial one, exactly.
    `ordered`: cell by cell in output order; otherwise after sorting both by cell."""
    ref = union([reference], prefix, kind)
    got = union(ranks, prefix, kind)
    checks.check(set(ref) == set(got), f"{prefix}{kind}: arrays {sorted(got)} instead of {sorted(ref)}")
    if "corners" not in got or len(got["corners"]) != len(ref["corners"]):
        checks.check(False, f"{prefix}{kind}: {len(got.get('corners', []))} cells in all instead of "
                            f"{len(ref['corners'])}")
        return
    order_ref = np.arange(len(ref["corners"])) if ordered else cell_order(ref["corners"])
    order_got = np.arange(len(got["corners"])) if ordered else cell_order(got["corners"])
    for name in sorted(set(ref) & set(got)):
        a, b = ref[name][order_ref], got[name][order_got]
        same = np.array_equal(a, b)
        detail = ""
        if not same and a.shape == b.shape and a.dtype.kind == "f":
            detail = f" (largest difference {np.abs(a - b).max():.3g})"
        checks.check(same, f"{prefix}{kind}: array {name} differs from serial{detail}")


def total_power(data, prefix):
    corners = data[prefix + "corners"]
    areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    return float((data[prefix + "cell_Radiosity"].sum(axis=1) * areas).sum())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", required=True)
    parser.add_argument("--ranks", type=int, required=True)
    parser.add_argument("--mpiexec", required=True)
    parser.add_argument("--pvbatch", required=True)
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--work", required=True)
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    for old in glob.glob(os.path.join(args.work, "*.npz")):
        os.remove(old)
    name = f"Parallel.{args.case}.{args.ranks}"
    checks = Checks()
    check = checks.check
    pvbatch = [args.pvbatch, "--force-offscreen-rendering", SCRIPT, "--plugin", args.plugin]
    mpi = [args.mpiexec, "--allow-run-as-root", "--oversubscribe", "-n", str(args.ranks),
           args.pvbatch, "--symmetric", "--force-offscreen-rendering", SCRIPT, "--plugin", args.plugin]
    out = os.path.join(args.work, args.case)
    extra = ["--paths", "400000"] if args.case == "abort" else []
    run(mpi + ["--case", args.case, "--out", out] + extra, f"{args.ranks} ranks")
    ranks = load(out)
    check(len(ranks) == args.ranks, f"{len(ranks)} ranks wrote results instead of {args.ranks}")

    if args.case in ("whole", "split"):
        run(pvbatch + ["--case", "whole", "--out", os.path.join(args.work, "serial")], "serial")
        reference = load(os.path.join(args.work, "serial"))[0]
        for f in (0, 14, 29):
            prefix = f"f{f}_"
            cells = [int(r[prefix + "e_cells"]) for r in ranks]
            if args.case == "whole":
                check(cells[0] == int(reference[prefix + "e_cells"]) and sum(cells[1:]) == 0,
                      f"frame {f}: elements per rank {cells}: rank 0 should hold all "
                      f"{int(reference[prefix + 'e_cells'])}")
            else:
                check(all(c > 0 for c in cells), f"frame {f}: elements per rank {cells}: every rank "
                                                  "holds part of the scene and must output some")
            lights = [int(r[prefix + "light_cells"]) for r in ranks]
            check(lights[0] == int(reference[prefix + "light_cells"]) and sum(lights[1:]) == 0,
                  f"frame {f}: Light cells per rank {lights}: rank 0 outputs the light")
            points = [int(r[prefix + "sensor_points"]) for r in ranks]
            serial_points = int(reference[prefix + "sensor_points"])
            check(serial_points == 16 and points[0] == serial_points and sum(points[1:]) == 0,
                  f"frame {f}: sensors per rank {points}, serial {serial_points}: rank 0 outputs "
                  "all 16")
            for name in ("Irradiance", "DaylightAutonomy"):
                key = prefix + "sensor_" + name
                check(key in ranks[0] and np.array_equal(ranks[0][key], reference[key]),
                      f"frame {f}: the sensors' {name} on rank 0 differs from the serial one")
            for r, data in enumerate(ranks):
                check(int(data[prefix + "frame"]) == f, f"rank {r}: FrameIndex {data[prefix + 'frame']} at time {f}")
                check(int(data[prefix + "solves"]) == 1, f"rank {r}: SolveCount {data[prefix + 'solves']}")
            for kind in ("e", "p"):
                compare(checks, reference, ranks, prefix, kind, ordered=args.case == "whole")
            serial_power = total_power(reference, prefix + "e_")
            power = sum(total_power(r, prefix + "e_") for r in ranks if int(r[prefix + "e_cells"]) > 0)
            check(abs(power - serial_power) <= 1e-9 * serial_power,
                  f"frame {f}: total power {power} W against {serial_power} W in serial")
        if args.case == "split":
            for r, data in enumerate(ranks):
                check(float(data["own_excess"]) < 1e-9,
                      f"rank {r}: an element lies {float(data['own_excess']):.3g} m farther from this "
                      "rank's own piece of the scene than from the whole scene: it comes from "
                      "another rank's cells")
    elif args.case == "time":
        for r, data in enumerate(ranks):
            solves = [int(data[f"s{s}_solves"]) for s in range(5)]
            check(solves == [1] * 5, f"rank {r}: SolveCount {solves} over five time requests, expected 1")
            frames = [int(data[f"s{s}_frame"]) for s in range(5)]
            check(frames == [0, 29, 14, 29, 0], f"rank {r}: frames {frames}")
            check(int(data["seed_solves"]) == 2, f"rank {r}: SolveCount {data['seed_solves']} after a new Seed")
            check(len(data["errors"]) == 0, f"rank {r}: errors {list(data['errors'])}")
        mine = union(ranks, "s1_", "e")
        first = union(ranks, "s0_", "e")
        check("cell_Radiosity" in mine and not np.array_equal(mine["cell_Radiosity"], first["cell_Radiosity"]),
              "frames 0 and 29 show the same radiosity")
    elif args.case == "abort":
        for r, data in enumerate(ranks):
            errors = list(data["abort_errors"])
            check(any("aborted" in e for e in errors), f"rank {r}: no abort reported ({errors})")
            check(int(data["abort_e_cells"]) == 0, f"rank {r}: {int(data['abort_e_cells'])} elements after the abort")
            check(int(data["after_solves"]) == 1, f"rank {r}: SolveCount {data['after_solves']} after the abort, "
                                                  "expected 1 (the aborted solve does not count)")
            check(len(data["errors"]) == 0, f"rank {r}: errors after the abort: {list(data['errors'])}")
        check(sum(int(r["after_e_cells"]) for r in ranks) > 0, "no elements from the solve after the abort")
    elif args.case == "bad":
        for r, data in enumerate(ranks):
            errors = list(data["bad_errors"])
            check(any("Reflectance" in e and "rank 1" in e for e in errors),
                  f"rank {r}: no error naming Reflectance on rank 1's piece ({errors})")
            check(int(data["bad_e_cells"]) == 0, f"rank {r}: output after the error")
            errors = list(data["memory_errors"])
            check(any("memory limit" in e for e in errors), f"rank {r}: no memory-limit error ({errors})")
            if r != 1:
                check(any("rank 1" in e for e in errors), f"rank {r}: the error does not name rank 1 ({errors})")
            check(int(data["memory_e_cells"]) == 0, f"rank {r}: output after the memory error")
    checks.finish(name)


if __name__ == "__main__":
    main()

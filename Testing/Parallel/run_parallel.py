#!/usr/bin/python3
"""Runs one parallel test: the serial reference in plain pvbatch, then the case on R
ranks under mpiexec (pvbatch --symmetric), each bounded by a timeout, and compares what every
rank wrote (pvbatch_parallel.py). Exits non-zero with one line per failed check.

    run_parallel.py --case whole|split|time|abort|abortalone|waitlimit|bad --ranks R --mpiexec M --pvbatch P \
        --plugin MovingLightRadiosity.so --work DIR

whole: the union of the ranks' outputs is the serial output bit for bit, cell by cell, and
       rank 0 holds it all (the input was whole on rank 0), its Sensors too (also in split).
split: the Scene is spread by RedistributeDataSet; every rank outputs cells, lying on its own
       piece of the scene; the union, sorted by cell, equals serial in every array, and the
       total power too.
time:  five time requests and no new solve on any rank; a new Seed solves once more.
abort: rank 0 aborts mid-solve (plain SetAbortExecute, during the proxy's UpdatePipeline of
       every port): every rank reports the abort, outputs nothing and has AbortExecute clear;
       asking again with nothing changed solves on no rank; a change solves on every rank.
abortalone: the same abort, then rank 0 alone updates and sets AbortExecute between updates:
       rank 0 solves nothing alone (no rank hangs), and the next solve, on every rank, is
       aborted on every rank; a change then solves on every rank, once.
waitlimit: after a solve, rank 0 alone sets a property and updates, under
       MLR_RANK_WAIT_LIMIT=4: rank 0 reports the ranks it waits for, then aborts the job with
       an error saying so, rather than hanging.
bad:   rank 1's piece lacks Reflectance: every rank reports an error naming it; rank 1 alone
       over its memory limit: every rank reports the limit. No rank hangs (the timeout).
chunks: 30 frames in 4 chunks of 8 (overlap 1): rank k mod R holds chunk k's frames (0-6,
       7-14, 15-22, 23-29) and outputs them whole, the other ranks nothing, and the union of
       the ranks' outputs is the serial output bit for bit in every frame.
fewchunks: the same with 4 frames in 2 chunks of 2: the first rank holds frame 0 alone,
       which it must not show at the other frames' time steps.
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
# A case takes 10 to 20 s on the shared 2-core machine; a rank left waiting in a collective
# waits forever, so the run is killed well before ctest's TIMEOUT, with what it printed.
TIMEOUT = 120


def run(command, what, timeout=TIMEOUT, env=None, may_fail=False):
    """Runs `command` in its own process group, killing the group on timeout. Returns its
    output, and with `may_fail` its exit code too instead of failing on a non-zero one."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True, start_new_session=True, env=env)
    try:
        output, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        output, _ = process.communicate()
        sys.exit(f"{what}: no answer within {timeout} s (a rank hangs?): {' '.join(command)}\n"
                 f"{(output or '')[-4000:]}")
    if may_fail:
        return output, process.returncode
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


def wait_limit(checks, args, command):
    """waitlimit: rank 0 updates alone and, MLR_RANK_WAIT_LIMIT seconds on, aborts the job
    with a message naming the ranks it waited for, after a report halfway."""
    limit = 4
    env = dict(os.environ, MLR_RANK_WAIT_LIMIT=str(limit))
    output, code = run(command, f"{args.ranks} ranks", args.timeout, env=env, may_fail=True)
    others = "rank 1" if args.ranks == 2 else "ranks " + ", ".join(map(str, range(1, args.ranks - 1))) + \
        f" and {args.ranks - 1}"
    waiting = f"rank 0 of {args.ranks} has waited"
    checks.check(code != 0, f"the job exited with 0: rank 0 updating alone was not stopped\n{output[-3000:]}")
    checks.check("rank 0 solved alone" not in output, "rank 0 solved alone")
    checks.check(output.count(waiting) >= 2 and f"for {others} to start the solve" in output,
                 f"no report and error naming {others} from rank 0:\n{output[-3000:]}")
    checks.check(f"MLR_RANK_WAIT_LIMIT is {limit}" in output and "aborting the MPI job" in output,
                 f"no error stating the wait limit:\n{output[-3000:]}")
    solved = load(os.path.join(args.work, args.case))
    checks.check(len(solved) >= args.ranks - 1 and all(int(r["first_solves"]) == 1 for r in solved),
                 "the solve before rank 0 went alone did not succeed on every rank that wrote results")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", required=True)
    parser.add_argument("--ranks", type=int, required=True)
    parser.add_argument("--mpiexec", required=True)
    parser.add_argument("--pvbatch", required=True)
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--timeout", type=float, default=TIMEOUT,
                        help="seconds the MPI run may take before it is killed as hung")
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
    extra = ["--paths", "400000"] if args.case.startswith("abort") else []
    if args.case == "waitlimit":
        wait_limit(checks, args, mpi + ["--case", args.case, "--out", out])
        checks.finish(name)
        return
    run(mpi + ["--case", args.case, "--out", out] + extra, f"{args.ranks} ranks", args.timeout)
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
    elif args.case in ("chunks", "fewchunks"):
        run(pvbatch + ["--case", args.case, "--out", os.path.join(args.work, "serial")], "serial")
        reference = load(os.path.join(args.work, "serial"))[0]
        # The frames each chunk finishes: up to the overlap before its end (1 frame here).
        finished = ([(0, 7), (7, 15), (15, 23), (23, 30)] if args.case == "chunks"
                    else [(0, 1), (1, 4)])
        for f in range(finished[-1][1]):
            prefix = f"f{f}_"
            owner = next(k for k, (b, e) in enumerate(finished) if b <= f < e) % args.ranks
            cells = [int(r[prefix + "e_cells"]) for r in ranks]
            serial_cells = int(reference[prefix + "e_cells"])
            check(cells[owner] == serial_cells and sum(cells) == serial_cells,
                  f"frame {f}: elements per rank {cells}: rank {owner} should hold all {serial_cells}")
            for r, data in enumerate(ranks):
                check(int(data[prefix + "frame"]) == f, f"rank {r}: FrameIndex {data[prefix + 'frame']} at time {f}")
                check(int(data[prefix + "solves"]) == 1, f"rank {r}: SolveCount {data[prefix + 'solves']}")
            for kind in ("e", "p"):
                compare(checks, reference, ranks, prefix, kind, ordered=True)
        for r, data in enumerate(ranks):
            check(len(data["errors"]) == 0, f"rank {r}: errors {list(data['errors'])}")
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
    elif args.case in ("abort", "abortalone"):
        def nothing_solved(prefix, r, data):
            cells = [int(data[f"{prefix}{k}_cells"]) for k in ("e", "p", "light")]
            check(cells == [0, 0, 0], f"rank {r}: {prefix}: Elements, Patches, Light cells {cells}, "
                                      "expected none")
            check(int(data[prefix + "solves"]) == 0, f"rank {r}: {prefix}: SolveCount "
                                                     f"{int(data[prefix + 'solves'])}, expected 0")

        def reports_abort(prefix, r, data):
            errors = list(data[prefix + "errors"])
            check(len(errors) > 0 and all("aborted" in e for e in errors),
                  f"rank {r}: {prefix}: errors {errors}, expected only the abort's")

        for r, data in enumerate(ranks):
            reports_abort("abort_", r, data)
            nothing_solved("abort_", r, data)
            check(int(data["abort_abort_flag"]) == 0, f"rank {r}: AbortExecute still set after the "
                                                      "aborted solve")
            if args.case == "abort":
                nothing_solved("again_", r, data)
                reports_abort("again_", r, data)
            else:
                nothing_solved("alone_", r, data)
                if r == 0:
                    reports_abort("alone_", r, data)
                else:
                    check(len(data["alone_errors"]) == 0,
                          f"rank {r}: errors {list(data['alone_errors'])} while rank 0 updated alone")
                check(int(data["alone_abort_flag"]) == (1 if r == 0 else 0),
                      f"rank {r}: AbortExecute {int(data['alone_abort_flag'])} after rank 0 alone set it")
                # Rank 0's abort, set between updates, stops the next solve on every rank.
                reports_abort("pending_", r, data)
                nothing_solved("pending_", r, data)
                check(int(data["pending_abort_flag"]) == 0, f"rank {r}: AbortExecute still set after "
                                                            "the aborted solve")
            check(int(data["after_solves"]) == 1, f"rank {r}: SolveCount {data['after_solves']} after the "
                                                  "abort, expected 1 (an aborted solve does not count)")
            check(len(data["errors"]) == 0, f"rank {r}: errors after the abort: {list(data['errors'])}")
        # What every rank reported, it reported alike: no rank executed alone.
        for prefix in ("abort_", "again_") if args.case == "abort" else ("abort_", "pending_"):
            counts = [len(data[prefix + "errors"]) for data in ranks]
            check(len(set(counts)) == 1, f"{prefix}: errors per rank {counts}: the ranks did not execute alike")
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

#!/usr/bin/python3
"""Scale-out on ParaView's MPI engine: the paper's configuration (the shipped
Cornell box remeshed to 2,686 patches, 30 light positions, N = 600,000, k = 1, lambda = 0.25,
full reuse) solved by pvbatch --symmetric under mpiexec as

- 1 rank x 1 thread, 2 ranks x 1 thread (with the speed-up), and 1 rank x 2 threads;

printing for each the solve's wall time, the filter's whole update, and the cost of gathering
the inputs over the ranks and of the sums over ranks (with the waits for the slower rank) as
a share of the solve. It also checks that every run gives the same radiosity (the solve is
bit-identical for any number of ranks and threads).

    Benchmarks/parallel_benchmark.py --plugin build/.../MovingLightRadiosity.so [--quick]

The same file is the script each rank runs (--rank-script). --quick runs a small
configuration (PatchSize 0.12, 20,000 paths) in seconds."""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.environ.get("MLR_DATA_DIR", os.path.join(HERE, os.pardir, "Data"))
TIMEOUT = 3600


def rank_script(args):
    """One rank's solve: writes its statistics (rank 0) as JSON to args.out."""
    import hashlib

    from paraview.simple import LoadPlugin, XMLPolyDataReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkParallelCore import vtkMultiProcessController

    LoadPlugin(args.plugin, remote=False, ns=globals())
    controller = vtkMultiProcessController.GetGlobalController()
    rank = controller.GetLocalProcessId() if controller else 0
    box = XMLPolyDataReader(FileName=[os.path.join(DATA, "cornell_box.vtp")])
    light = XMLPolyDataReader(FileName=[os.path.join(DATA, "cornell_light.vtp")])
    trajectory = XMLPolyDataReader(FileName=[os.path.join(DATA, "cornell_trajectory.vtp")])
    for source in (box, light, trajectory):
        source.UpdatePipeline()
    radiosity = MovingLightRadiosity(  # noqa: F821
        Scene=box, Light=light, Trajectory=trajectory, PatchSize=args.patch_size,
        NumberOfPaths=args.paths, GatheringRatio=1.0, FirstBounceSurvival=0.25,
        ReuseShooting=1, ReuseGathering=1, Seed=1, NumberOfThreads=args.threads)
    start = time.perf_counter()
    cpu = time.process_time()
    radiosity.UpdatePipeline(time=0.0)
    update = time.perf_counter() - start
    cpu = time.process_time() - cpu
    elements = radiosity.GetClientSideObject().GetOutputDataObject(0)
    fields = elements.GetFieldData()

    def field(name):
        array = fields.GetArray(name)
        return array.GetValue(0) if array is not None else 0.0

    with open(f"{args.out}.cpu{rank}", "w") as f:
        f.write(repr(cpu))
    if rank == 0:
        digest = hashlib.sha256(vtk_to_numpy(elements.GetCellData().GetArray("Radiosity")).tobytes())
        stats = {name: field(name) for name in (
            "SecondsRemeshing", "SecondsSetup", "SecondsShooting", "SecondsGathering",
            "SecondsSolve", "SecondsGatheringInputs", "SecondsReducing", "Ranks", "Patches",
            "Elements", "Frames")}
        stats["SecondsUpdate"] = update
        stats["RadiosityDigest"] = digest.hexdigest()[:16]
        with open(args.out, "w") as f:
            json.dump(stats, f)


def measure(args, ranks, threads, work):
    out = os.path.join(work, f"r{ranks}t{threads}.json")
    command = [args.mpiexec, "--allow-run-as-root", "--oversubscribe", "-n", str(ranks),
               args.pvbatch, "--symmetric", "--force-offscreen-rendering", os.path.abspath(__file__),
               "--rank-script", "--plugin", args.plugin, "--out", out, "--threads", str(threads),
               "--paths", str(args.paths), "--patch-size", str(args.patch_size)]
    subprocess.run(command, check=True, timeout=TIMEOUT, stdout=subprocess.DEVNULL)
    with open(out) as f:
        stats = json.load(f)
    # CPU seconds of each rank's update (its own work, plus MPI's polling while it waits).
    cpus = []
    for r in range(ranks):
        with open(f"{out}.cpu{r}") as f:
            cpus.append(float(f.read()))
    stats["CpuSecondsPerRank"] = cpus
    return stats


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plugin", required=True, help="MovingLightRadiosity.so")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--rank-script", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--out", help=argparse.SUPPRESS)
    parser.add_argument("--threads", type=int, default=1, help=argparse.SUPPRESS)
    parser.add_argument("--paths", type=int, default=None)
    parser.add_argument("--patch-size", type=float, default=None)
    parser.add_argument("--mpiexec", default=shutil.which("mpiexec"))
    parser.add_argument("--pvbatch", default=shutil.which("pvbatch"))
    args = parser.parse_args()
    if args.paths is None:
        args.paths = 20000 if args.quick else 600000
    if args.patch_size is None:
        # 0.046 m remeshes the Cornell box into 2,686 patches, the paper's count.
        args.patch_size = 0.12 if args.quick else 0.046
    if args.rank_script:
        rank_script(args)
        return
    if not args.mpiexec or not args.pvbatch:
        sys.exit("mpiexec and pvbatch are needed (apt-get install paraview openmpi-bin)")
    work = tempfile.mkdtemp(prefix="mlr-parallel-benchmark-")
    try:
        runs = {}
        for ranks, threads in ((1, 1), (2, 1), (1, 2)):
            runs[(ranks, threads)] = measure(args, ranks, threads, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    first = runs[(1, 1)]
    print(f"Cornell box: {int(first['Patches'])} patches, {int(first['Elements'])} elements, "
          f"{int(first['Frames'])} frames, N = {args.paths}, k = 1, lambda = 0.25, full reuse; "
          f"remeshing {first['SecondsRemeshing']:.2f} s (not in the solve)")
    print(f"{'configuration':<22}{'solve s':>9}{'update s':>10}{'speed-up':>10}"
          f"{'gather inputs':>15}{'sums over ranks':>17}  CPU s per rank")
    for (ranks, threads), s in runs.items():
        solve = s["SecondsSolve"]
        print(f"{f'{ranks} rank x {threads} thread':<22}{solve:>9.2f}{s['SecondsUpdate']:>10.2f}"
              f"{first['SecondsSolve'] / solve:>9.2f}x"
              f"{100 * s['SecondsGatheringInputs'] / solve:>14.2f}%"
              f"{100 * s['SecondsReducing'] / solve:>16.2f}%  "
              + ", ".join(f"{c:.2f}" for c in s["CpuSecondsPerRank"]))
    print(f"(machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}; the sums "
          "include the waits for the slower rank)")
    digests = {s["RadiosityDigest"] for s in runs.values()}
    print("radiosity identical in every run: " + ("yes" if len(digests) == 1 else f"NO ({digests})"))
    if len(digests) != 1:
        sys.exit(1)


if __name__ == "__main__":
    main()

"""One rank of the parallel tests, run by run_parallel.py as

    mpiexec -n R pvbatch --symmetric --force-offscreen-rendering pvbatch_parallel.py \
        --plugin MovingLightRadiosity.so --case CASE --out PREFIX

(or by plain pvbatch for the serial reference). The scene is the shipped Cornell box, the
light and its 30-position trajectory, remeshed coarsely (PatchSize 0.12) and solved with few
paths on one thread per rank. Each rank writes what it outputs to PREFIX.rank<r>.npz, and
run_parallel.py compares. Cases:

- whole: the readers' outputs (whole on rank 0) go in as they are;
- split: the Scene goes through RedistributeDataSet (and ExtractSurface back to polydata), so
  every rank holds some of its cells; each rank also writes how much farther its elements lie
  from its own piece of the scene than from the whole scene (0: they come from its cells);
- time: steps through frames without a new solve (SolveCount), then a new Seed solves again;
- abort: rank 0 sets AbortExecute from a progress event once the solve is under way, during
  the proxy's UpdatePipeline (every port); every rank then updates again with nothing changed;
- abortalone: the same abort, then rank 0 alone updates again and sets AbortExecute between
  updates; every rank then updates with a new NumberOfPaths;
- waitlimit: a solve, then rank 0 alone sets a property and updates (run with
  MLR_RANK_WAIT_LIMIT set: rank 0 names the ranks it waits for, then aborts the job);
- bad: rank 1's Scene piece lacks the Reflectance array (the ranks' pieces disagree), then,
  with consistent pieces, rank 1 alone has a memory limit the solve does not fit in;
- chunks: FramesPerChunk 8 (4 chunks of the 30 frames), every time step in turn: each rank
  holds the frames of the chunks it solved and outputs them whole, nothing at the others';
- fewchunks: 4 positions in chunks of 2, so that the first chunk finishes frame 0 alone: its
  rank still outputs nothing at the other time steps.
"""
import argparse
import os
import re
import sys

import numpy as np

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--plugin", required=True)
parser.add_argument("--case", required=True, choices=["whole", "split", "time", "abort", "abortalone", "waitlimit", "bad",
                             "chunks", "fewchunks"])
parser.add_argument("--out", required=True, help="prefix of the .rank<r>.npz files written")
parser.add_argument("--paths", type=int, default=20000)
args = parser.parse_args()

from paraview.simple import (ExtractSurface, LoadPlugin, PassArrays, RedistributeDataSet,  # noqa: E402
                             XMLPolyDataReader)
from vtkmodules.util.misc import calldata_type  # noqa: E402
from parallel_support import record_mesh  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.util.vtkConstants import VTK_STRING  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkStaticCellLocator  # noqa: E402
from vtkmodules.vtkParallelCore import vtkMultiProcessController  # noqa: E402

LoadPlugin(args.plugin, remote=False, ns=globals())
controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId() if controller else 0
ranks = controller.GetNumberOfProcesses() if controller else 1

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, "Data")
FRAMES = (0.0, 14.0, 29.0)
box = XMLPolyDataReader(FileName=[os.path.join(DATA, "cornell_box.vtp")])
light = XMLPolyDataReader(FileName=[os.path.join(DATA, "cornell_light.vtp")])
trajectory = XMLPolyDataReader(FileName=[os.path.join(DATA, "cornell_trajectory.vtp")])
scene = box
if args.case in ("split", "bad"):
    scene = ExtractSurface(Input=RedistributeDataSet(Input=box))
if args.case == "bad" and rank == 1:
    # Only this rank's piece loses its material.
    scene = PassArrays(Input=scene, CellDataArrays=["vtkOriginalCellIds"], PointDataArrays=[])
radiosity = MovingLightRadiosity(Scene=scene, Light=light, Trajectory=trajectory,  # noqa: F821
                                 PatchSize=0.12, NumberOfPaths=args.paths, NumberOfThreads=1,
                                 Seed=1)
if args.case in ("whole", "split"):
    # A grid of sensors facing up across the middle of the box (a Plane's Normals).
    from paraview.simple import Plane
    box.UpdatePipeline()
    x0, x1, y0, y1, z0, z1 = box.GetDataInformation().GetBounds()
    zc = 0.5 * (z0 + z1)
    xm, ym = 0.1 * (x1 - x0), 0.1 * (y1 - y0)
    radiosity.Sensors = Plane(Origin=[x0 + xm, y0 + ym, zc], Point1=[x1 - xm, y0 + ym, zc],
                              Point2=[x0 + xm, y1 - ym, zc], XResolution=3, YResolution=3)
algorithm = radiosity.GetClientSideObject()
errors = []


@calldata_type(VTK_STRING)
def on_error(caller, event, message):
    errors.append(str(message))


algorithm.AddObserver("ErrorEvent", on_error)
results = {"ranks": np.array(ranks)}


def field(data, name):
    array = data.GetFieldData().GetArray(name)
    return array.GetValue(0) if array is not None else -1


def record(prefix, time):
    """Every array of the three outputs at `time`, under prefix."""
    radiosity.UpdatePipeline(time=time)
    elements = algorithm.GetOutputDataObject(0)
    patches = algorithm.GetOutputDataObject(1)
    results[prefix + "solves"] = np.array(field(elements, "SolveCount"))
    results[prefix + "frame"] = np.array(field(elements, "FrameIndex"))
    results[prefix + "light_cells"] = np.array(algorithm.GetOutputDataObject(2).GetNumberOfCells())
    sensors = algorithm.GetOutputDataObject(3)
    results[prefix + "sensor_points"] = np.array(sensors.GetNumberOfPoints())
    if sensors.GetNumberOfPoints() > 0:
        for name in ("Irradiance", "DaylightAutonomy"):
            results[prefix + "sensor_" + name] = vtk_to_numpy(sensors.GetPointData().GetArray(name))
    for name, data in (("e", elements), ("p", patches)):
        record_mesh(results, prefix + name, data)
    return elements


def distances(data, centroids):
    """The distance from each centroid to the nearest cell of `data`."""
    from vtkmodules.vtkCommonCore import mutable
    locator = vtkStaticCellLocator()
    locator.SetDataSet(data)
    locator.BuildLocator()
    closest = [0.0, 0.0, 0.0]
    cell, sub, d2 = mutable(0), mutable(0), mutable(0.0)
    result = []
    for centroid in centroids:
        locator.FindClosestPoint(list(centroid), closest, cell, sub, d2)
        result.append(float(d2) ** 0.5)
    return np.array(result)


def own_piece_excess(elements):
    """How much farther an element's centroid lies from this rank's own piece of the scene
    than from the whole scene (0 when its nearest input cell is this rank's: the Cornell box
    has non-planar quads, so elements lie up to mm off the cells' bilinear surfaces)."""
    if elements.GetNumberOfCells() == 0:
        return 0.0
    piece = scene.GetClientSideObject().GetOutputDataObject(0)
    if piece.GetNumberOfCells() == 0:
        return float("inf")
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    whole = vtkXMLPolyDataReader()
    whole.SetFileName(os.path.join(DATA, "cornell_box.vtp"))
    whole.Update()
    centroids = results["f0_e_corners"].mean(axis=1)
    return float((distances(piece, centroids) - distances(whole.GetOutput(), centroids)).max())


if args.case in ("whole", "split"):
    for f in FRAMES:
        elements = record(f"f{int(f)}_", f)
    if args.case == "split":
        results["own_excess"] = np.array(own_piece_excess(algorithm.GetOutputDataObject(0)))
elif args.case == "chunks":
    radiosity.FramesPerChunk = 8
    for f in range(30):
        record(f"f{f}_", float(f))
elif args.case == "fewchunks":
    from paraview.simple import Line
    radiosity.Trajectory = Line(Point1=[0.12, 0.5478, 0.0995], Point2=[0.436, 0.5478, 0.4595],
                                Resolution=3)
    radiosity.FramesPerChunk = 2
    for f in range(4):
        record(f"f{f}_", float(f))
elif args.case == "time":
    for step, f in enumerate((0.0, 29.0, 14.0, 29.0, 0.0)):
        record(f"s{step}_", f)
    radiosity.Seed = 2
    record("seed_", 14.0)
elif args.case in ("abort", "abortalone"):
    state = {"armed": True}

    def on_progress(caller, event):
        # Past remeshing (the first 5%): the solve's phases are running. The plain setter, as
        # a script or a user's Abort does it.
        if rank == 0 and state["armed"] and caller.GetProgress() > 0.2:
            state["armed"] = False
            caller.SetAbortExecute(1)

    def outcome(prefix):
        """What every port holds now, the solves so far and the errors since the last call."""
        results[prefix + "errors"] = np.array(errors[:])
        errors.clear()
        # The client-side object is wrapped as its VTK base class here; PrintSelf has it all.
        results[prefix + "solves"] = np.array(int(re.search(r"SolveCount: (\d+)", str(algorithm))[1]))
        results[prefix + "abort_flag"] = np.array(algorithm.GetAbortExecute())
        for port, name in enumerate(("e", "p", "light")):
            results[f"{prefix}{name}_cells"] = np.array(
                algorithm.GetOutputDataObject(port).GetNumberOfCells())

    observer = algorithm.AddObserver("ProgressEvent", on_progress)
    # As ParaView's Apply: the proxy updates every output port, one after the other, so the
    # ports after the aborted one ask again at once.
    radiosity.UpdatePipeline(time=0.0)
    algorithm.RemoveObserver(observer)
    outcome("abort_")
    if args.case == "abort":
        # Every rank asks again with nothing changed: the abort holds, on every rank alike.
        radiosity.UpdatePipeline(time=14.0)
        algorithm.UpdatePiece(rank, ranks, 0)
        outcome("again_")
    else:
        # Rank 0 alone asks again, every port and another time, as a script that updates on
        # one rank only; then, between updates, rank 0 alone sets AbortExecute (an abort with
        # nothing running), which must stop the next solve on every rank, not rank 0 alone.
        if rank == 0:
            radiosity.UpdatePipeline(time=14.0)
            algorithm.UpdatePiece(rank, ranks, 0)
            algorithm.SetAbortExecute(1)
        outcome("alone_")
        radiosity.NumberOfPaths = 300000
        radiosity.UpdatePipeline(time=0.0)
        outcome("pending_")
    # A change solves again, on every rank, once.
    radiosity.NumberOfPaths = 20000
    record("after_", 0.0)
elif args.case == "waitlimit":
    # A solve on every rank, then rank 0 alone changes a property and updates: it waits for
    # the others, says which, and past MLR_RANK_WAIT_LIMIT aborts the job.
    record("first_", 0.0)
    if rank == 0:
        radiosity.Seed = 2
        radiosity.UpdatePipeline(time=0.0)
        print("rank 0 solved alone", flush=True)
elif args.case == "bad":
    record("bad_", 0.0)
    results["bad_errors"] = np.array(errors[:])
    errors.clear()
    # Consistent pieces again, but rank 1 alone is over its memory limit.
    radiosity.Scene = ExtractSurface(Input=RedistributeDataSet(Input=box))
    if rank == 1:
        radiosity.MemoryLimit = 1
    record("memory_", 0.0)
    results["memory_errors"] = np.array(errors[:])
    errors.clear()

results["errors"] = np.array(errors)
np.savez(f"{args.out}.rank{rank}.npz", **results)
print(f"rank {rank} of {ranks}: wrote {args.out}.rank{rank}.npz", flush=True)

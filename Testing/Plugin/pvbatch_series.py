"""Saving the animation as ParaView users do, in pvbatch: MergeBlocks + SaveData(.pvd,
WriteTimeSteps=1) writes one .vtu per light position and a .pvd listing their times; the
series reads back (PVD reader) with the expected times and arrays and the same Radiosity as
the filter, and writing every step solved only once.

    pvbatch --force-offscreen-rendering pvbatch_series.py --plugin MovingLightRadiosity.so"""
import os
import tempfile
import xml.etree.ElementTree as ElementTree

import numpy

import plugin_test_support as support

args = support.parse_arguments(__doc__.splitlines()[0])

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.Series")
check = checks.check

ELEMENT_ARRAYS = {"Radiosity", "DirectRadiosity", "IndirectRadiosity", "RadiosityFront",
                  "RadiosityBack", "Reflectance", "PatchId"}
TIMES = [float(i) for i in range(support.POSITIONS)]


def solve_count(data):
    array = data.GetFieldData().GetArray("SolveCount")
    return array.GetValue(0) if array else None


radiosity, sources = support.box_pipeline()
radiosity.UpdatePipeline(time=0.0)
solves = solve_count(servermanager.Fetch(radiosity))
merged = MergeBlocks(Input=radiosity)

with tempfile.TemporaryDirectory(prefix="mlr-plugin-series-") as folder:
    pvd = os.path.join(folder, "animation.pvd")
    SaveData(pvd, proxy=merged, WriteTimeSteps=1)

    check(os.path.isfile(pvd), f"SaveData wrote no {pvd}")
    entries = []
    if os.path.isfile(pvd):
        entries = [(float(e.get("timestep")), e.get("file"))
                   for e in ElementTree.parse(pvd).getroot().iter("DataSet")]
    check([t for t, _ in entries] == TIMES, f"the .pvd lists the times {[t for t, _ in entries]}")
    files = [os.path.join(folder, f) for _, f in entries]
    check(all(f.endswith(".vtu") and os.path.isfile(f) for f in files),
          f"the .pvd names missing or non-.vtu files: {[os.path.relpath(f, folder) for f in files]}")

    reader = PVDReader(FileName=pvd)
    reader.UpdatePipelineInformation()
    check(list(reader.TimestepValues) == TIMES, f"read back, the times are {list(reader.TimestepValues)}")
    check(ELEMENT_ARRAYS <= set(reader.CellData.keys()),
          f"read back, the cell arrays are {sorted(reader.CellData.keys())}, expected {sorted(ELEMENT_ARRAYS)}")

    for time in (0.0, 5.0, 9.0):
        radiosity.UpdatePipeline(time=time)
        original = servermanager.Fetch(radiosity)
        reader.UpdatePipeline(time=time)
        saved = servermanager.Fetch(reader)
        where = f"time {time}"
        check(saved.IsA("vtkUnstructuredGrid"), f"{where}: read back a {saved.GetClassName()}")
        check(saved.GetNumberOfCells() == original.GetNumberOfCells(),
              f"{where}: {saved.GetNumberOfCells()} cells saved, {original.GetNumberOfCells()} computed")
        saved_radiosity = saved.GetCellData().GetArray("Radiosity")
        if check(saved_radiosity is not None, f"{where}: no Radiosity read back"):
            check(numpy.array_equal(vtk_to_numpy(saved_radiosity),
                                    vtk_to_numpy(original.GetCellData().GetArray("Radiosity"))),
                  f"{where}: the saved Radiosity is not the filter's")
        frame = saved.GetFieldData().GetArray("FrameIndex")
        check(frame is not None and frame.GetValue(0) == int(time),
              f"{where}: the saved field data shows frame {frame.GetValue(0) if frame else None}")

    radiosity.UpdatePipeline(time=3.0)
    check(solve_count(servermanager.Fetch(radiosity)) == solves,
          "writing the time steps solved again instead of reading the cached solve")

checks.finish()

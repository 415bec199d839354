"""The plugin's scene reader in pvbatch, as File > Open and paraview.simple meet it:

- ParaView's reader factory offers "Radiosity scene with materials" for .obj, .gltf, .glb and
  .ply files, next to ParaView's own readers;
- RadiositySceneReader opens an OBJ + MTL written here (two reflectors, a lamp with Ke, faces
  before and after each usemtl): each cell carries its material's Kd as Reflectance, pi x Ke
  as Emission, its MaterialId, and MaterialNames and EmissionUnits are in the field data;
- the shipped Data/CornellBox-Original.obj opens with its lamp (Ke 17 12 4) emitting;
- a missing file gives an error and no cells, not a crash.

    pvbatch --force-offscreen-rendering pvbatch_scenereader.py --plugin MovingLightRadiosity.so"""
import math
import os
import shutil
import tempfile

import plugin_test_support as support

args = support.parse_arguments(__doc__.splitlines()[0])

from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: F401,F403,E402 (LoadPlugin adds the reader here)

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.SceneReader")
check = checks.check
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "Data")

# --- File > Open ---------------------------------------------------------------------------
factory = servermanager.vtkSMProxyManager.GetProxyManager().GetReaderFactory()
session = servermanager.ActiveConnection.Session
folder = tempfile.mkdtemp(prefix="mlr-plugin-scene-")
for extension in ("obj", "gltf", "glb", "ply"):
    path = os.path.join(folder, "probe." + extension)
    open(path, "w").close()
    readers = factory.GetPossibleReaders(path, session)
    offered = [(readers.GetString(i), readers.GetString(i + 1))
               for i in range(0, readers.GetLength(), 3)]
    check(("sources", "RadiositySceneReader") in offered,
          f".{extension}: File > Open does not offer sources/RadiositySceneReader")
file_types = factory.GetSupportedFileTypes(session)
check("Radiosity scene with materials (*.obj *.gltf *.glb *.ply)" in file_types,
      "File > Open's file types lack 'Radiosity scene with materials (*.obj *.gltf *.glb *.ply)'")

# --- An OBJ + MTL ----------------------------------------------------------------------------
with open(os.path.join(folder, "room.mtl"), "w") as mtl:
    mtl.write("newmtl white\nKd 0.725 0.71 0.68\nnewmtl red\nKd 0.63 0.065 0.05\n"
              "newmtl lamp\nKd 0.78 0.78 0.78\nKe 17 12 4\n")
with open(os.path.join(folder, "room.obj"), "w") as obj:
    obj.write("mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
              "usemtl white\nf 1 2 3\nf 1 3 4\nusemtl red\nf 1 4 3\n"
              "v 0.4 0.4 0.9\nv 0.6 0.4 0.9\nv 0.6 0.6 0.9\nv 0.4 0.6 0.9\n"
              "usemtl lamp\nf -1 -2 -3 -4\n")


def cells(data, name):
    array = data.GetCellData().GetArray(name)
    if array is None:
        return None
    return [array.GetTuple(i) for i in range(array.GetNumberOfTuples())]


def strings(data, name):
    array = data.GetFieldData().GetAbstractArray(name)
    if array is None:
        return None
    return [array.GetValue(i) for i in range(array.GetNumberOfValues())]


reader = RadiositySceneReader(FileName=os.path.join(folder, "room.obj"))  # noqa: F405
check(reader.GetProperty("MemoryLimit") is not None and reader.MemoryLimit == 0,
      "the reader has no MemoryLimit property defaulting to 0 (half of the physical memory)")
reader.UpdatePipeline()
data = servermanager.Fetch(reader)
check(data.GetNumberOfCells() == 4, f"room.obj gave {data.GetNumberOfCells()} cells, expected 4")
check(strings(data, "MaterialNames") == ["white", "red", "lamp"],
      f"MaterialNames {strings(data, 'MaterialNames')}, expected ['white', 'red', 'lamp']")
check(strings(data, "EmissionUnits") == ["W/m^2"], f"EmissionUnits {strings(data, 'EmissionUnits')}")
ids = cells(data, "MaterialId")
check(ids == [(0,), (0,), (1,), (2,)], f"MaterialId {ids}, expected 0 0 1 2")
expected_kd = [(0.725, 0.71, 0.68)] * 2 + [(0.63, 0.065, 0.05), (0.78, 0.78, 0.78)]
expected_emission = [(0, 0, 0)] * 3 + [(17 * math.pi, 12 * math.pi, 4 * math.pi)]
for name, expected in (("Reflectance", expected_kd), ("Emission", expected_emission)):
    values = cells(data, name) or []
    check(len(values) == 4 and all(math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-12)
                                   for row, want in zip(values, expected) for a, b in zip(row, want)),
          f"{name} {values}, expected {expected}")

# --- The shipped Cornell box ---------------------------------------------------------------
cornell = RadiositySceneReader(FileName=os.path.join(DATA, "CornellBox-Original.obj"))  # noqa: F405
cornell.UpdatePipeline()
box = servermanager.Fetch(cornell)
names = strings(box, "MaterialNames") or []
check("light" in names and box.GetNumberOfCells() == 16,
      f"CornellBox-Original.obj: {box.GetNumberOfCells()} cells, materials {names}")
if "light" in names:
    lamp = [e for e, (m,) in zip(cells(box, "Emission"), cells(box, "MaterialId"))
            if names[int(m)] == "light"]
    check(len(lamp) == 1 and math.isclose(lamp[0][0], 17 * math.pi, rel_tol=1e-9),
          f"the Cornell lamp's Emission is {lamp}, expected pi x (17, 12, 4)")

# --- A missing file --------------------------------------------------------------------------
missing = RadiositySceneReader(FileName=os.path.join(folder, "nowhere.obj"))  # noqa: F405
missing.UpdatePipeline()
check(servermanager.Fetch(missing).GetNumberOfCells() == 0, "a missing file gave cells")

Delete(missing)  # noqa: F405
shutil.rmtree(folder, ignore_errors=True)
checks.finish()

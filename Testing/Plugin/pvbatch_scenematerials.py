"""The plugin's scene reader and the filter's LightMaterial against the command line, on the
shipped Data/CornellBox-Original.obj:

- RadiositySceneReader opens the OBJ + MTL; Moving Light Radiosity with LightMaterial "light"
  (no Light input), a straight path (PathStart, PathEnd, NumberOfPositions) and a fixed
  seed, paths and threads solves it;
- moving-light-radiosity --scene ... --light-material light with the same path, seed, paths
  and threads writes a .pvd series;
- every frame has the same elements, cell by cell (count, corners), and the same Radiosity to
  float32 precision: the two are one computation, not two estimates that agree on average;
- every element carries the Kd of the material it lies on (from the .mtl), the lamp is gone
  from the elements, and the Light output is the lamp at each frame's place with the power
  pi x Ke x area;
- with the path left at its defaults, the lamp starts where the OBJ has it, not at Path Start
  (the middle of the scene's -x face).

    pvbatch --force-offscreen-rendering pvbatch_scenematerials.py --plugin MovingLightRadiosity.so \
        --cli moving-light-radiosity"""
import os
import shutil
import subprocess
import tempfile
import xml.etree.ElementTree as ElementTree

import plugin_test_support as support

args = support.parse_arguments(
    __doc__.splitlines()[0],
    lambda parser: parser.add_argument("--cli", required=True, help="the moving-light-radiosity program"))

from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: F401,F403,E402
import numpy  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader  # noqa: E402

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.SceneMaterials")
check = checks.check

OBJ = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "Data",
                   "CornellBox-Original.obj")
# The lamp's centroid is (0, 1.9641, 0.0003): the path crosses the ceiling under it.
START, END = (-0.5, 1.9641, -0.4), (0.5, 1.9641, 0.4)
FRAMES, PATHS, SEED, THREADS = 4, 20000, 7, 2
# Kd of CornellBox-Original.mtl
WHITE = (0.725, 0.71, 0.68)
KD = {"floor": WHITE, "ceiling": WHITE, "backWall": WHITE, "shortBox": WHITE, "tallBox": WHITE,
      "leftWall": (0.63, 0.065, 0.05), "rightWall": (0.14, 0.45, 0.091), "light": (0.78, 0.78, 0.78)}


def triple(values):
    return ",".join(repr(float(v)) for v in values)


# --- The command line ------------------------------------------------------------------------
folder = tempfile.mkdtemp(prefix="mlr-plugin-materials-")
series = os.path.join(folder, "cornell.pvd")
run = subprocess.run(
    [args.cli, "--scene", OBJ, "--light-material", "light", "--from", triple(START),
     "--to", triple(END), "--frames", str(FRAMES), "--paths", str(PATHS), "--seed", str(SEED),
     "--threads", str(THREADS), "--output", series],
    capture_output=True, text=True, timeout=240)
check(run.returncode == 0, f"moving-light-radiosity exited with {run.returncode}:\n{run.stderr}")
cli_frames = []
if run.returncode == 0:
    for entry in ElementTree.parse(series).getroot().iter("DataSet"):
        reader = vtkXMLUnstructuredGridReader()
        reader.SetFileName(os.path.join(folder, entry.get("file")))
        reader.Update()
        frame = reader.GetOutput().NewInstance()
        frame.DeepCopy(reader.GetOutput())
        cli_frames.append((float(entry.get("timestep")), frame))
check(len(cli_frames) == FRAMES, f"the command line wrote {len(cli_frames)} frames, expected {FRAMES}")

# --- ParaView ---------------------------------------------------------------------------------
scene = RadiositySceneReader(FileName=OBJ)  # noqa: F405
radiosity = MovingLightRadiosity(  # noqa: F405
    # --from is where the command line's lamp starts: PathStart, not where the OBJ has it.
    Scene=scene, LightMaterial="light", PathFromLightMaterial=0, PathStart=list(START),
    PathEnd=list(END), NumberOfPositions=FRAMES, NumberOfPaths=PATHS, Seed=SEED,
    NumberOfThreads=THREADS)
radiosity.UpdatePipeline(0.0)
times = list(radiosity.TimestepValues)
check(times == [t for t, _ in cli_frames],
      f"the filter's times {times}, the command line's {[t for t, _ in cli_frames]}")


def cell_array(data, name):
    array = data.GetCellData().GetArray(name)
    return None if array is None else vtk_to_numpy(array)


def corners(data):
    """Each cell's corner coordinates, (cells, 3, 3): the meshes' point numbering differs
    (the filter splits points at creases for smooth shading), their corners must not."""
    points = vtk_to_numpy(data.GetPoints().GetData()).astype(numpy.float64)
    if data.IsA("vtkPolyData"):
        connectivity = vtk_to_numpy(data.GetPolys().GetConnectivityArray())
    else:
        connectivity = vtk_to_numpy(data.GetCells().GetConnectivityArray())
    return points[connectivity.reshape(-1, 3)]


for index, (time, cli) in enumerate(cli_frames):
    if index >= len(times):
        break
    radiosity.UpdatePipeline(times[index])
    elements = servermanager.Fetch(radiosity)
    where = f"frame {index} (t = {time})"
    check(elements.GetNumberOfCells() == cli.GetNumberOfCells() > 0,
          f"{where}: the filter has {elements.GetNumberOfCells()} elements, "
          f"the command line {cli.GetNumberOfCells()}")
    if elements.GetNumberOfCells() != cli.GetNumberOfCells():
        continue
    gap = numpy.abs(corners(elements) - corners(cli)).max()
    check(gap < 1e-6, f"{where}: element corners differ by up to {gap}")
    ours, theirs = cell_array(elements, "Radiosity"), cell_array(cli, "Radiosity")
    if ours is None or theirs is None:
        check(False, f"{where}: Radiosity missing (filter {ours is not None}, command line {theirs is not None})")
        continue
    check(ours.max() > 0, f"{where}: the filter's Radiosity is all zero")
    # Both are float32 copies of the same doubles: equal to the last bit or one ulp.
    tolerance = 2 * numpy.finfo(numpy.float32).eps * numpy.maximum(numpy.abs(theirs), 1e-30)
    worst = (numpy.abs(ours - theirs) - tolerance).max()
    check(worst <= 0, f"{where}: Radiosity differs from the command line's by more than float32 "
          f"precision (max excess {worst}, max |difference| {numpy.abs(ours - theirs).max()})")
    light = servermanager.Fetch(radiosity, idx=2)
    centre = vtk_to_numpy(light.GetPoints().GetData()).mean(axis=0) if light.GetNumberOfPoints() else None
    f = index / (FRAMES - 1)
    expected = numpy.array(START) + f * (numpy.array(END) - numpy.array(START))
    check(centre is not None and numpy.abs(centre - expected).max() < 1e-3,
          f"{where}: the Light output is centred at {centre}, the path at {expected}")
    # Its power is the material's emission, pi Ke area (Ke 17 12 4, 0.4676 x 0.3777).
    power = cell_array(light, "Power")
    lamp_power = numpy.pi * numpy.array([17.0, 12.0, 4.0]) * (2 * 0.2338) * (0.1892 + 0.1885)
    check(power is not None and numpy.allclose(power.sum(axis=0), lamp_power, rtol=1e-6),
          f"{where}: the Light output's Power sums to "
          f"{None if power is None else power.sum(axis=0)}, expected pi Ke area = {lamp_power}")

# --- Materials ----------------------------------------------------------------------------
# Each element's reflectance is the Kd of the reader's cell it lies on (found by the cell's
# plane and extent containing the element's centroid).
radiosity.UpdatePipeline(times[0] if times else 0.0)
elements = servermanager.Fetch(radiosity)
read = servermanager.Fetch(scene)
names_array = read.GetFieldData().GetAbstractArray("MaterialNames")
names = [names_array.GetValue(i) for i in range(names_array.GetNumberOfValues())]
material_ids = cell_array(read, "MaterialId")
reflectance = cell_array(elements, "Reflectance")
check(reflectance is not None and reflectance.shape[1:] == (3,),
      "the Elements lack a 3-component Reflectance")
if reflectance is not None and material_ids is not None:
    from vtkmodules.vtkCommonCore import reference
    from vtkmodules.vtkCommonDataModel import vtkCellLocator
    locator = vtkCellLocator()
    locator.SetDataSet(read)
    locator.BuildLocator()
    centroids = corners(elements).mean(axis=1)
    seen, wrong, on_lamp = set(), [], 0
    closest, cell, sub, distance = [0.0] * 3, reference(0), reference(0), reference(0.0)
    for e, centroid in enumerate(centroids):
        locator.FindClosestPoint(list(centroid), closest, cell, sub, distance)
        name = names[int(material_ids[int(cell)])]
        if name == "light":
            on_lamp += 1
            continue
        seen.add(name)
        if numpy.abs(reflectance[e] - numpy.array(KD[name])).max() > 1e-6:
            wrong.append((e, name, tuple(reflectance[e])))
    check(not wrong, f"{len(wrong)} elements do not carry their material's Kd, e.g. {wrong[:3]}")
    check(seen == set(KD) - {"light"}, f"elements on the materials {sorted(seen)}")
    check(on_lamp == 0, f"{on_lamp} elements lie on the lamp, which LightMaterial takes out")
    for name, colour in KD.items():
        if name != "light":
            check(any(numpy.abs(reflectance - numpy.array(colour)).max(axis=1) < 1e-6),
                  f"no element has {name}'s Kd {colour}")

# --- The path left at its defaults -----------------------------------------------------------
# Path Start defaults to the middle of the scene's -x face; the lamp starts where the OBJ has it
# (its centroid), not there, and moves from there to Path End.
LAMP = numpy.array([[-0.2338, 1.9641, 0.1892], [-0.2338, 1.9641, -0.1885],
                    [0.2338, 1.9641, -0.1885], [0.2338, 1.9641, 0.1892]])
defaults = MovingLightRadiosity(  # noqa: F405
    Scene=scene, LightMaterial="light", NumberOfPositions=3, NumberOfPaths=PATHS, Seed=SEED,
    NumberOfThreads=THREADS)
check(numpy.abs(numpy.array(defaults.PathStart) - LAMP.mean(axis=0)).max() > 0.5,
      f"Path Start defaults to {list(defaults.PathStart)}, near the lamp: the check proves nothing")
for time, expected in ((0.0, LAMP.mean(axis=0)), (2.0, numpy.array(defaults.PathEnd))):
    defaults.UpdatePipeline(time)
    position = vtk_to_numpy(servermanager.Fetch(defaults).GetFieldData().GetArray("LightPosition"))[0]
    check(numpy.abs(position - expected).max() < 1e-5,
          f"t = {time}: the lamp is at {position}, expected {expected}")
defaults.UpdatePipeline(0.0)
light = servermanager.Fetch(defaults, idx=2)
points = vtk_to_numpy(light.GetPoints().GetData()) if light.GetNumberOfPoints() else numpy.zeros((0, 3))
check(points.shape == LAMP.shape and numpy.abs(numpy.sort(points, axis=0) - numpy.sort(LAMP, axis=0)).max() < 1e-5,
      f"the first time step's Light is {points.tolist()}, not the lamp where the OBJ has it")

shutil.rmtree(folder, ignore_errors=True)
checks.finish()

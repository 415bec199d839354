"""Time steps of the plugin's filter in pvbatch, from ParaView sources only (Box as Scene, a
Plane as Light, a Line with resolution 9 as Trajectory):

- TimestepValues has one entry per trajectory point (10);
- UpdatePipeline(time=t) + Fetch at three times gives that frame: FrameIndex, LightPosition,
  the lit spot under the light on the floor, Radiosity different from the other frames; a
  time between two steps gives the step below; the Patches output follows too;
- going back and forth in time solves nothing again (SolveCount and the arrays unchanged);
- changing a property (Seed, then NumberOfPaths) or an input (the trajectory) solves again;
- disconnecting the Trajectory (Trajectory = None) puts the light back on Path Start to Path
  End, and disconnecting the Sensors empties the Sensors output;
- a Scene with time steps of its own (a .pvd series whose floor rises) is solved once, at its
  first time step, whatever time another consumer of the reader asks it for.

    pvbatch --force-offscreen-rendering pvbatch_time.py --plugin MovingLightRadiosity.so"""
import os
import tempfile

import numpy

import plugin_test_support as support

args = support.parse_arguments(__doc__.splitlines()[0])

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.Time")
check = checks.check

ELEMENT_ARRAYS = ("Radiosity", "DirectRadiosity", "IndirectRadiosity", "RadiosityFront",
                  "RadiosityBack", "Reflectance", "PatchId")

radiosity, sources = support.box_pipeline()
radiosity.UpdatePipelineInformation()
check(list(radiosity.TimestepValues) == [float(i) for i in range(support.POSITIONS)],
      f"TimestepValues {list(radiosity.TimestepValues)}, expected {support.POSITIONS} steps 0, 1, ...")


def field(data, name):
    array = data.GetFieldData().GetArray(name)
    if array is None:
        return None
    return array.GetTuple(0) if array.GetNumberOfComponents() > 1 else array.GetValue(0)


def fetch(time, port=0):
    """The output of `port` at `time`, as a script would get it."""
    radiosity.UpdatePipeline(time=time)
    return servermanager.Fetch(radiosity, idx=port)


def lit_spot(data):
    """Centre (x, y) of the brightest floor cells (those above half the floor's maximum of
    direct radiosity): where the light shines down."""
    points = vtk_to_numpy(data.GetPoints().GetData())
    triangles = vtk_to_numpy(data.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    centres = points[triangles].mean(axis=1)
    direct = numpy.linalg.norm(vtk_to_numpy(data.GetCellData().GetArray("DirectRadiosity")), axis=1)
    floor = numpy.abs(centres[:, 2] - support.FLOOR_Z) < 1e-6
    bright = floor & (direct >= 0.5 * direct[floor].max())
    return centres[bright, :2].mean(axis=0)


frames = {}
for time in (0.0, 9.0, 4.0):
    data = fetch(time)
    frame = int(time)
    where = f"time {time}"
    check(data.GetNumberOfCells() > 0, f"{where}: empty Elements output")
    check(field(data, "FrameIndex") == frame, f"{where}: FrameIndex {field(data, 'FrameIndex')}, "
          f"expected {frame}")
    position = field(data, "LightPosition")
    check(position is not None and numpy.allclose(position, support.light_position(frame), atol=1e-9),
          f"{where}: LightPosition {position}, expected {support.light_position(frame)}")
    missing = [a for a in ELEMENT_ARRAYS if data.GetCellData().GetArray(a) is None]
    check(not missing, f"{where}: Elements lack the cell arrays {missing}")
    if missing:
        continue
    spot = lit_spot(data)
    expected = numpy.array(support.light_position(frame)[:2])
    # The spot lies under the light, give or take the noise of 20000 paths: within one
    # light width, while the three frames' positions are 0.28 to 0.85 apart.
    check(numpy.linalg.norm(spot - expected) < 2 * support.LIGHT_HALF,
          f"{where}: the floor is brightest around {spot}, not under the light at {expected}")
    frames[frame] = {"radiosity": vtk_to_numpy(data.GetCellData().GetArray("Radiosity")).copy(),
                     "solves": field(data, "SolveCount")}

if len(frames) == 3:
    solves = {f: v["solves"] for f, v in frames.items()}
    check(len(set(solves.values())) == 1, f"SolveCount changed between time steps: {solves}")
    for a, b in ((0, 9), (0, 4), (4, 9)):
        difference = numpy.abs(frames[a]["radiosity"] - frames[b]["radiosity"]).max()
        check(difference > 0.05 * frames[a]["radiosity"].max(),
              f"Radiosity of frames {a} and {b} differ by at most {difference}: the light did not move")
    first_solves = solves[0]

    # Back and forth: served from the cache, identical arrays, no new solve.
    for time in (9.0, 0.0, 9.0, 4.0, 0.0):
        data = fetch(time)
        frame = int(time)
        check(field(data, "SolveCount") == first_solves,
              f"going back to time {time} solved again (SolveCount {field(data, 'SolveCount')}, "
              f"was {first_solves})")
        again = vtk_to_numpy(data.GetCellData().GetArray("Radiosity"))
        check(numpy.array_equal(again, frames[frame]["radiosity"]),
              f"time {time} shows other values the second time")

    # Between two steps: the step at or below.
    data = fetch(4.5)
    check(field(data, "FrameIndex") == 4, f"time 4.5 shows frame {field(data, 'FrameIndex')}, expected 4")
    data = fetch(0.0)
    check(field(data, "FrameIndex") == 0, "time 0 after 4.5 is not frame 0")

    # The Patches output follows the time of its own update.
    patches = fetch(9.0, port=1)
    check(patches.GetNumberOfCells() > 0 and patches.GetCellData().GetArray("Radiosity") is not None,
          "the Patches output has no cells or no Radiosity")
    check(field(patches, "FrameIndex") == 9, f"Patches at time 9 show frame {field(patches, 'FrameIndex')}")
    check(field(patches, "SolveCount") == first_solves, "updating the Patches output solved again")

    # A property changes: one new solve, then served from the cache again.
    for name, value in (("Seed", 1), ("NumberOfPaths", support.TEST_PATHS + 5000)):
        before = field(fetch(4.0), "SolveCount")
        setattr(radiosity, name, value)
        data = fetch(4.0)
        after = field(data, "SolveCount")
        check(after == before + 1, f"setting {name} = {value} made {after - before} solves, expected 1")
        check(field(data, "FrameIndex") == 4, f"after setting {name}, time 4 shows another frame")
        check(not numpy.array_equal(vtk_to_numpy(data.GetCellData().GetArray("Radiosity")),
                                    frames[4]["radiosity"]),
              f"setting {name} = {value} left Radiosity unchanged")
        check(field(fetch(9.0), "SolveCount") == after, f"after setting {name}, a new time solved again")

    # An input changes: the trajectory gets 5 points, the time steps follow.
    before = field(fetch(0.0), "SolveCount")
    sources["trajectory"].Resolution = 4
    radiosity.UpdatePipelineInformation()
    check(list(radiosity.TimestepValues) == [0.0, 1.0, 2.0, 3.0, 4.0],
          f"after Resolution = 4 the time steps are {list(radiosity.TimestepValues)}")
    data = fetch(4.0)
    check(field(data, "SolveCount") == before + 1, "a new trajectory did not solve again")
    check(numpy.allclose(field(data, "LightPosition"), support.PATH_END),
          f"the last of 5 positions is {field(data, 'LightPosition')}, expected {support.PATH_END}")

    # Disconnected optional inputs reach the filter (null_on_empty): the Trajectory's 5 positions
    # give way to Path Start to Path End.
    radiosity.NumberOfPositions = 3
    radiosity.Trajectory = None
    radiosity.UpdatePipelineInformation()
    check(list(radiosity.TimestepValues) == [0.0, 1.0, 2.0],
          f"without a Trajectory the time steps are {list(radiosity.TimestepValues)}, expected "
          "the 3 of Path Start to Path End")
    data = fetch(2.0)
    check(numpy.allclose(field(data, "LightPosition"), radiosity.PathEnd),
          f"without a Trajectory the last position is {field(data, 'LightPosition')}, expected "
          f"Path End {list(radiosity.PathEnd)}")
    radiosity.Sensors = Plane(Origin=[-0.2, -0.2, 0.0], Point1=[0.2, -0.2, 0.0],
                              Point2=[-0.2, 0.2, 0.0])
    check(fetch(0.0, port=3).GetNumberOfPoints() == 4, "the Plane's 4 sensors are not in the output")
    radiosity.Sensors = None
    check(fetch(0.0, port=3).GetNumberOfPoints() == 0,
          "after Sensors = None the Sensors output still has points")


def write_rising_floor(directory, steps):
    """A .pvd series of a 2 x 2 floor at z = 0.2 t, t = 0 ... steps - 1."""
    from vtkmodules.vtkFiltersSources import vtkPlaneSource
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    entries = []
    for t in range(steps):
        plane = vtkPlaneSource()
        plane.SetOrigin(-1, -1, 0.2 * t)
        plane.SetPoint1(1, -1, 0.2 * t)
        plane.SetPoint2(-1, 1, 0.2 * t)
        writer = vtkXMLPolyDataWriter()
        writer.SetInputConnection(plane.GetOutputPort())
        writer.SetFileName(os.path.join(directory, f"floor_{t}.vtp"))
        writer.Write()
        entries.append(f'<DataSet timestep="{t}" file="floor_{t}.vtp"/>')
    path = os.path.join(directory, "floor.pvd")
    with open(path, "w") as out:
        out.write('<?xml version="1.0"?><VTKFile type="Collection" version="0.1"><Collection>' +
                  "".join(entries) + "</Collection></VTKFile>")
    return path


# A temporal Scene whose reader another consumer (a view, here a script) updates at each time:
# the filter solved again at every step, with the scene of the time the reader ran last.
with tempfile.TemporaryDirectory() as directory:
    reader = PVDReader(FileName=write_rising_floor(directory, 5))
    x, y, z = -0.1, -0.1, 2.5
    lamp = Plane(Origin=[x, y, z], Point1=[x, y + 0.2, z], Point2=[x + 0.2, y, z])
    moving = MovingLightRadiosity(Scene=reader, Light=lamp, NumberOfPaths=support.TEST_PATHS,
                                  PathStart=[-0.5, 0, z], PathEnd=[0.5, 0, z], NumberOfPositions=5)
    solves = set()
    for time in (0.0, 2.0, 4.0, 1.0):
        reader.UpdatePipeline(time=time)
        moving.UpdatePipeline(time=time)
        data = servermanager.Fetch(moving)
        solves.add(field(data, "SolveCount"))
        check(abs(data.GetBounds()[4]) < 1e-9 and abs(data.GetBounds()[5]) < 1e-9,
              f"at time {time} the solved floor spans z {data.GetBounds()[4:]}, expected the "
              "series' first step at z = 0")
        check(field(data, "FrameIndex") == int(time),
              f"at time {time} the filter shows frame {field(data, 'FrameIndex')}")
    check(len(solves) == 1, f"stepping through a temporal Scene solved again: SolveCount {solves}")

checks.finish()

"""Light rigs and the sun from Python: inputs built from vtkmodules
sources, the arrays and time steps the filter gives back.

Run by ctest with PYTHONPATH set to the build's Python folder (see CMakeLists.txt), or by hand:
    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 -m pytest Testing/Python
"""
import math
import os
import sys

import pytest

from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkIntArray, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
from vtkmodules.vtkFiltersCore import vtkAppendPolyData
from vtkmodules.vtkFiltersSources import vtkCubeSource, vtkLineSource, vtkPlaneSource

from movinglightradiosity import vtkMovingLightRadiosity

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from vtk_messages import recorded  # noqa: E402

FRAMES = 3
ELEMENT_ARRAYS = ("Radiosity", "DirectRadiosity", "IndirectRadiosity", "EmittedRadiosity",
                  "Reflectance", "Color")


def output(source):
    source.Update()
    return source.GetOutput()


def time_steps(algorithm):
    algorithm.UpdateInformation()
    return algorithm.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS())


def field(data, name):
    array = data.GetFieldData().GetArray(name)
    assert array is not None, f"no field array {name}"
    return array.GetTuple(0) if array.GetNumberOfComponents() > 1 else array.GetValue(0)


def square_light(centre, side=0.2):
    """A square facing down (-z): (P1 - O) x (P2 - O) points down."""
    x, y, z = centre
    plane = vtkPlaneSource()
    plane.SetOrigin(x - side / 2, y - side / 2, z)
    plane.SetPoint1(x - side / 2, y + side / 2, z)
    plane.SetPoint2(x + side / 2, y - side / 2, z)
    return plane


def cell_array(name, values, components=1, array_type=vtkDoubleArray):
    array = array_type()
    array.SetName(name)
    array.SetNumberOfComponents(components)
    for value in values:
        array.InsertNextTuple(value if components > 1 else (value,))
    return array


@pytest.fixture(scope="module")
def rig():
    """A unit cube (grey 0.5 without a Reflectance array) lit by two lights inside it, each
    moving along its own line: LightId 0 and 1 with their own LightPower."""
    cube = vtkCubeSource()
    cube.SetBounds(0, 1, 0, 1, 0, 1)
    scene = output(cube)

    # A connection does not keep its producer alive: the sources are held until updated.
    squares = [square_light((0.5, 0.5, 0.9)), square_light((0.5, 0.5, 0.6))]
    lights = vtkAppendPolyData()
    for square in squares:
        lights.AddInputConnection(square.GetOutputPort())
    light = output(lights)
    light.GetCellData().AddArray(cell_array("LightId", (0, 1), array_type=vtkIntArray))
    light.GetCellData().AddArray(cell_array("LightPower", ((2, 3, 4), (4, 3, 2)), 3))

    paths = vtkAppendPolyData()  # one polyline per light, in LightId order
    lines = []
    for start, end in (((0.3, 0.3, 0.9), (0.7, 0.7, 0.9)), ((0.7, 0.3, 0.6), (0.3, 0.7, 0.6))):
        lines.append(vtkLineSource())
        lines[-1].SetPoint1(start)
        lines[-1].SetPoint2(end)
        lines[-1].SetResolution(FRAMES - 1)
        paths.AddInputConnection(lines[-1].GetOutputPort())
    trajectory = output(paths)
    trajectory.GetPointData().AddArray(
        cell_array("Power", (1, 0.5, 1, 1, 1, 1)))

    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(scene)
    radiosity.SetLightData(light)
    radiosity.SetTrajectoryData(trajectory)
    radiosity.SetNumberOfPaths(20000)
    radiosity.SetPatchSize(0.25)
    radiosity.SetNumberOfThreads(2)
    return {"filter": radiosity, "trajectory": trajectory}


def test_rig_time_steps_are_the_polylines_points(rig):
    assert time_steps(rig["filter"]) == tuple(float(i) for i in range(FRAMES))


def test_rig_arrays_and_posed_lights(rig):
    radiosity = rig["filter"]
    trajectory = rig["trajectory"]
    for frame in range(FRAMES):
        assert radiosity.UpdateTimeStep(float(frame))
        elements = radiosity.GetOutput(0)
        for name in ELEMENT_ARRAYS:
            assert elements.GetCellData().GetArray(name) is not None, name
        assert elements.GetCellData().GetArray("Radiosity").GetRange(-1)[1] > 0
        assert field(elements, "FrameIndex") == frame
        # The first light's centroid, where its polyline puts it.
        assert field(elements, "LightPosition") == pytest.approx(trajectory.GetPoint(frame))
        lights = radiosity.GetOutput(2)
        assert lights.GetNumberOfCells() == 2
        power = lights.GetCellData().GetArray("Power")
        assert power is not None
        factor = 0.5 if frame == 1 else 1.0  # the first light's Power in this frame
        assert power.GetTuple3(0) == pytest.approx((2 * factor, 3 * factor, 4 * factor))
        assert power.GetTuple3(1) == pytest.approx((4, 3, 2))
    assert radiosity.GetSolveCount() == 1


def test_rig_without_its_polyline_is_an_error(rig):
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(rig["filter"].GetInputDataObject(0, 0))
    radiosity.SetLightData(rig["filter"].GetInputDataObject(1, 0))
    line = vtkLineSource()
    line.SetResolution(FRAMES - 1)
    radiosity.SetTrajectoryData(output(line))  # one polyline for two lights
    errors = recorded(radiosity, "ErrorEvent")
    assert not radiosity.UpdateTimeStep(0.0)
    assert any("2 lights (LightId) but the Trajectory has 1 polyline:" in e for e in errors), errors
    assert radiosity.GetOutput(0).GetNumberOfCells() == 0


@pytest.fixture(scope="module")
def sun():
    """A 1 m ground plane facing up under the sun at elevations 30, 90 and 150 degrees
    (morning, noon, evening), from a line source's points as directions."""
    ground = vtkPlaneSource()
    ground.SetResolution(4, 4)
    directions = vtkLineSource()
    directions.SetPoint1(math.sqrt(3), 0, 1)
    directions.SetPoint2(-math.sqrt(3), 0, 1)
    directions.SetResolution(2)
    trajectory = output(directions)
    trajectory.GetPointData().AddArray(cell_array("SunElevation", (30, 90, 150)))
    trajectory.GetPointData().AddArray(cell_array("SunAzimuth", (90, 180, 270)))

    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(output(ground))
    radiosity.SetTrajectoryData(trajectory)
    radiosity.SetLightTypeToDirectional()
    radiosity.SetSunIrradiance(800)
    radiosity.SetNumberOfPaths(50000)
    radiosity.SetPatchSize(0.25)
    radiosity.SetNumberOfThreads(2)
    return radiosity


def test_night_follows_the_sun_paths_elevation_whatever_the_filters_up():
    """A Y-up scene: the Sun Path source set to Up 0, 1, 0 gives directions whose z is
    negative in the northern half of the sky, while the filter's Up stays +z. Judged across
    the filter's Up those suns were night; the Trajectory's SunElevation decides, and the
    disagreement is named."""
    ground = vtkPlaneSource()  # in the x-z plane, facing +y: a Y-up scene's ground
    ground.SetOrigin(-0.5, 0, 0.5)
    ground.SetPoint1(0.5, 0, 0.5)
    ground.SetPoint2(-0.5, 0, -0.5)
    trajectory = vtkPolyData()
    points = vtkPoints()
    for direction in ((0, 1, 0.5), (0, 1, -0.5), (0, -1, 0.5)):  # the last: below, y < 0
        points.InsertNextPoint(*direction)
    trajectory.SetPoints(points)
    trajectory.GetPointData().AddArray(cell_array("SunElevation", (63.4, 63.4, -63.4)))
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(output(ground))
    radiosity.SetTrajectoryData(trajectory)
    radiosity.SetLightTypeToDirectional()
    radiosity.SetNumberOfPaths(20000)
    radiosity.SetPatchSize(0.5)
    radiosity.SetNumberOfThreads(2)
    messages = recorded(radiosity, "WarningEvent")
    lit = []
    for frame in range(3):
        assert radiosity.UpdateTimeStep(float(frame))
        direct = radiosity.GetOutput(0).GetCellData().GetArray("DirectRadiosity")
        lit.append(max(direct.GetRange(1)[1], direct.GetRange(0)[1]))
    # Frame 1's sun has z < 0 but stands 63 degrees high: lit, as frame 0; frame 2 is night.
    assert lit[0] > 0 and lit[1] == pytest.approx(lit[0], rel=0.1) and lit[2] == 0, lit
    assert any("SunElevation and the filter's Up (0, 0, 1) disagree" in m and "frames 1, 2" in m
               for m in messages), messages
    assert any("in 1 of 3 frames, frame 2: that frame is night" in m for m in messages), messages


def test_sun_time_steps_and_field_data(sun):
    assert sun.GetLightType() == vtkMovingLightRadiosity.DIRECTIONAL_LIGHT
    assert time_steps(sun) == (0.0, 1.0, 2.0)
    elevations = (30, 90, 150)
    for frame, elevation in enumerate(elevations):
        assert sun.UpdateTimeStep(float(frame))
        elements = sun.GetOutput(0)
        for name in ELEMENT_ARRAYS:
            assert elements.GetCellData().GetArray(name) is not None, name
        assert field(elements, "SunElevation") == elevation
        assert field(elements, "SunAzimuth") == 90 * (frame + 1)
        s = math.radians(elevation)
        assert field(elements, "SunDirection") == pytest.approx((math.cos(s), 0, math.sin(s)))
        # Direct light on the ground: rho E sin(elevation), grey 0.5 (no Reflectance array).
        direct = elements.GetCellData().GetArray("DirectRadiosity")
        total = area = 0.0
        for cell in range(elements.GetNumberOfCells()):
            a = elements.GetCell(cell).ComputeArea()
            total += a * direct.GetComponent(cell, 1)
            area += a
        assert total / area == pytest.approx(0.5 * 800 * math.sin(s), rel=0.03)
        assert sun.GetOutput(2).GetNumberOfCells() == 0  # no area light to show


def test_a_two_sided_panel_says_what_arrives_on_each_side_in_every_frame():
    """A vertical panel facing +y under a sun 30 degrees high, from its front in frame 0 and
    its back in frames 1 and 2: it shows its back (lit more), so frame 0's Irradiance is the
    back's 0, while IrradianceFront holds the 800 cos 30 W/m^2 arriving in front."""
    panel = vtkPlaneSource()  # x-z plane, normal (P1 - O) x (P2 - O) = +y
    panel.SetOrigin(-0.5, 0, 0)
    panel.SetPoint1(-0.5, 0, 1)
    panel.SetPoint2(0.5, 0, 0)
    panel.SetResolution(2, 2)
    trajectory = vtkPolyData()
    points = vtkPoints()
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    for direction in ((0, c, s), (0, -c, s), (0, -c, s)):
        points.InsertNextPoint(*direction)
    trajectory.SetPoints(points)
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(output(panel))
    radiosity.SetTrajectoryData(trajectory)
    radiosity.SetLightTypeToDirectional()
    radiosity.SetSunIrradiance(800)
    radiosity.SetNumberOfPaths(200000)
    radiosity.SetPatchSize(0.5)
    radiosity.SetNumberOfThreads(2)
    expected = 800 * math.cos(math.radians(30))
    for frame, lit in ((0, "Front"), (1, "Back")):
        assert radiosity.UpdateTimeStep(float(frame))
        elements = radiosity.GetOutput(0)
        cells = elements.GetCellData()
        n = elements.GetNumberOfCells()
        efficacy = field(elements, "LuminousEfficacy")
        side = {name: [cells.GetArray("Irradiance" + name).GetTuple3(c) for c in range(n)]
                for name in ("Front", "Back")}
        dark = "Back" if lit == "Front" else "Front"
        assert all(rgb == (0, 0, 0) for rgb in side[dark]), (frame, dark)
        # Every element is an unbiased estimate of the same irradiance, from the paths that
        # land on it: their mean is within 4 standard errors, from their own spread.
        values = [rgb[0] for rgb in side[lit]]
        mean = sum(values) / n
        spread = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1))
        assert 0 < spread < 0.2 * expected, (frame, spread)
        assert abs(mean - expected) < 4 * spread / math.sqrt(n), (frame, mean, expected, spread)
        for c in range(n):
            # The panel shows its back in every frame, and lux follows each side's watts.
            assert cells.GetArray("Irradiance").GetTuple3(c) == side["Back"][c]
            for name in ("Front", "Back"):
                lux = cells.GetArray("Illuminance" + name).GetValue(c)
                assert lux == pytest.approx(efficacy * side[name][c][0], rel=1e-5, abs=1e-3)

"""The command line's sensors: --work-plane over a small open-top room lit by a uniform sky
and a lamp (the grid count, heights and illuminance arrays), --sensors FILE.vtp,
--da-threshold, the sensors' standard errors (series, summary and --stats), and their bad
inputs.

The room is 3 x 2 (x, y) and 2.5 high, floor facing up. With SPACING 0.5 the lattice
(i + 1/2) 0.5 puts 6 x 4 = 24 sensors inside the floor; the walls face inwards (never up) and
there is no ceiling, so the floor is the only upward face.

ctest sets MLR_CLI and MLR_DATA_DIR; by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps
"""
import json
import os
import xml.etree.ElementTree as ElementTree

import numpy
import pytest

from test_cli_rigs_and_sun import Polygons, run, write_points

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkFloatArray, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData, vtkUnstructuredGrid
from vtkmodules.vtkIOXML import (vtkXMLPolyDataReader, vtkXMLPolyDataWriter,
                                 vtkXMLUnstructuredGridWriter)

W, D, H = 3.0, 2.0, 2.5
HEIGHT, SPACING = 0.8, 0.5
EDH = 100.0
GROUND = (-2.0, 5.0, -2.0, 4.0)  # x0, x1, y0, y1: a ground around the room's footprint
FAST = ["--paths", "20000", "--threads", "2", "--patch-size", "0.5"]


def write_room(directory, ceiling=False):
    room = Polygons()
    room.add([(0, 0, 0), (W, 0, 0), (W, D, 0), (0, D, 0)])          # floor, facing up
    room.add([(0, 0, 0), (0, D, 0), (0, D, H), (0, 0, H)])          # x = 0, facing +x
    room.add([(W, 0, 0), (W, 0, H), (W, D, H), (W, D, 0)])          # x = W, facing -x
    room.add([(0, 0, 0), (0, 0, H), (W, 0, H), (W, 0, 0)])          # y = 0, facing +y
    room.add([(0, D, 0), (W, D, 0), (W, D, H), (0, D, H)])          # y = D, facing -y
    if ceiling:
        room.add([(0, 0, H), (0, D, H), (W, D, H), (W, 0, H)])      # facing down
    return room.write(directory / "room.vtp")


def write_wall(directory):
    return Polygons().add([(0, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1)]).write(directory / "wall.vtp")


def write_lamp(directory):
    c = (1.5, 1.0, 2.4)
    s = 0.2
    return Polygons().add([(c[0] - s, c[1] - s, c[2]), (c[0] - s, c[1] + s, c[2]),
                           (c[0] + s, c[1] + s, c[2]), (c[0] + s, c[1] - s, c[2])]).write(
        directory / "lamp.vtp")


def write_sensors(directory, points, normals, name="sensors.vtp"):
    data = vtkPolyData()
    pts = vtkPoints()
    for p in points:
        pts.InsertNextPoint(*p)
    data.SetPoints(pts)
    if normals is not None:
        array = vtkFloatArray()
        array.SetName("Normals")
        array.SetNumberOfComponents(3)
        for n in normals:
            array.InsertNextTuple3(*n)
        data.GetPointData().AddArray(array)
    writer = vtkXMLPolyDataWriter()
    writer.SetInputData(data)
    writer.SetFileName(str(directory / name))
    assert writer.Write()
    return str(directory / name)


def read_sensor_series(directory, collection="out/room_sensors.pvd"):
    path = directory / collection
    assert path.exists(), os.listdir(path.parent)
    frames = []
    for entry in ElementTree.parse(path).getroot().iter("DataSet"):
        reader = vtkXMLPolyDataReader()
        reader.SetFileName(str(path.parent / entry.get("file")))
        reader.Update()
        frames.append((float(entry.get("timestep")), reader.GetOutput()))
    return frames


def array(data, name):
    return vtk_to_numpy(data.GetPointData().GetArray(name))


def test_work_plane_under_the_sky_gives_the_grid_and_its_illuminance(tmp_path):
    result = run(["--scene", write_room(tmp_path), "--sky", "uniform",
                  "--sky-diffuse-horizontal", str(EDH), "--work-plane", f"{HEIGHT},{SPACING}",
                  "--output", "out/room.pvd"] + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    assert "24 sensors" in result.stdout
    # The sky alone: no shadow ray, 512 hemisphere rays per sensor (24 x 512 = 12,288).
    assert "sensors 0.00 M shadow, 0.01 M gathering rays" in result.stdout, result.stdout
    frames = read_sensor_series(tmp_path)
    assert len(frames) == 1
    sensors = frames[0][1]
    assert sensors.GetFieldData().GetArray("SensorShadowRays").GetValue(0) == 0
    assert sensors.GetFieldData().GetArray("SensorGatheringRays").GetValue(0) == 24 * 512
    assert sensors.GetNumberOfPoints() == 24
    points = vtk_to_numpy(sensors.GetPoints().GetData())
    assert numpy.allclose(points[:, 2], HEIGHT)
    assert sorted(set(numpy.round(points[:, 0], 6))) == pytest.approx([0.25, 0.75, 1.25, 1.75, 2.25, 2.75])
    assert sorted(set(numpy.round(points[:, 1], 6))) == pytest.approx([0.25, 0.75, 1.25, 1.75])
    assert numpy.allclose(array(sensors, "Normals"), [0, 0, 1])
    irradiance = array(sensors, "Irradiance")
    lux = array(sensors, "Illuminance")
    efficacy = sensors.GetFieldData().GetArray("LuminousEfficacy").GetValue(0)
    assert lux == pytest.approx(efficacy * (irradiance @ [0.2126, 0.7152, 0.0722]), rel=1e-5)
    # The sky through the open top, and the walls' light: less than E_dh, more than a tenth.
    assert numpy.all(irradiance[:, 1] < EDH) and numpy.all(irradiance[:, 1] > 0.1 * EDH)
    # The middle of the room sees more sky than its corners.
    centre = numpy.argmin(numpy.hypot(points[:, 0] - 1.25, points[:, 1] - 0.75))
    corner = numpy.argmin(numpy.hypot(points[:, 0] - 0.25, points[:, 1] - 0.25))
    assert irradiance[centre, 1] > irradiance[corner, 1]
    for name in ("DaylightAutonomy", "UDILow", "UDIUseful", "UDIHigh", "DirectSunHours"):
        assert sensors.GetPointData().GetArray(name) is not None, name
    shares = array(sensors, "UDILow") + array(sensors, "UDIUseful") + array(sensors, "UDIHigh")
    assert numpy.allclose(shares, 1)
    assert numpy.all(array(sensors, "DirectSunHours") == 0)
    # --sensor-rays sets the rays per sensor.
    result = run(["--scene", write_room(tmp_path), "--sky", "uniform", "--work-plane",
                  f"{HEIGHT},{SPACING}", "--sensor-rays", "64", "--output", "out/room.pvd"]
                 + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    sensors = read_sensor_series(tmp_path)[0][1]
    assert sensors.GetFieldData().GetArray("SensorGatheringRays").GetValue(0) == 24 * 64


def moving_lamp_args(tmp_path):
    """The closed room with a lamp moving over 3 frames and three sensors (two on the work
    plane, one on the wall at x = 2.9 facing in)."""
    points = [(1.5, 1.0, 0.8), (0.5, 0.5, 0.8), (2.9, 1.0, 1.2)]
    normals = [(0, 0, 1), (0, 0, 1), (-1, 0, 0)]
    return ["--scene", write_room(tmp_path, ceiling=True), "--light", write_lamp(tmp_path),
            "--from", "1.5,1,2.4", "--to", "1,0.8,2.4", "--frames", "3",
            "--sensors", write_sensors(tmp_path, points, normals),
            "--output", "out/room.pvd"] + FAST


def test_sensors_file_with_a_moving_lamp_and_the_threshold(tmp_path):
    args = moving_lamp_args(tmp_path)
    result = run(args, tmp_path)
    assert result.returncode == 0, result.stderr
    frames = read_sensor_series(tmp_path)
    assert len(frames) == 3
    lux = numpy.array([array(f, "Illuminance") for _, f in frames])
    assert numpy.all(lux > 0)
    # The lamp moves away from the first sensor.
    assert lux[0, 0] > lux[2, 0]
    # A threshold below every frame's illuminance: DA 1; above: 0.
    for threshold, expected in ((0.5 * lux.min(), 1.0), (2 * lux.max(), 0.0)):
        result = run(args + ["--da-threshold", str(threshold)], tmp_path)
        assert result.returncode == 0, result.stderr
        da = array(read_sensor_series(tmp_path)[0][1], "DaylightAutonomy")
        assert numpy.allclose(da, expected), (threshold, da)


def test_sensors_as_points_of_an_unstructured_grid_without_cells(tmp_path):
    """A .vtu of points and no cells is a sensors file like a .vtp: the same sensors, the same
    values (the surface of no cells would have dropped its points)."""
    args = moving_lamp_args(tmp_path)
    result = run(args, tmp_path)
    assert result.returncode == 0, result.stderr
    expected = array(read_sensor_series(tmp_path)[1][1], "Illuminance")
    polygons = vtkXMLPolyDataReader()
    polygons.SetFileName(args[args.index("--sensors") + 1])
    polygons.Update()
    grid = vtkUnstructuredGrid()
    grid.SetPoints(polygons.GetOutput().GetPoints())
    grid.GetPointData().ShallowCopy(polygons.GetOutput().GetPointData())
    assert grid.GetNumberOfCells() == 0
    writer = vtkXMLUnstructuredGridWriter()
    writer.SetInputData(grid)
    writer.SetFileName(str(tmp_path / "sensors.vtu"))
    assert writer.Write()
    args[args.index("--sensors") + 1] = str(tmp_path / "sensors.vtu")
    result = run(args, tmp_path)
    assert result.returncode == 0, result.stderr
    assert numpy.array_equal(array(read_sensor_series(tmp_path)[1][1], "Illuminance"), expected)


def test_the_sensors_series_and_stats_carry_their_standard_errors(tmp_path):
    # The default 16 error batches: every frame's sensors have IrradianceStdError (RGB) and
    # IlluminanceStdError, the summary a line for the lit sensors, and --stats their figures
    # per frame; with one batch none of them.
    args = moving_lamp_args(tmp_path)
    stats = tmp_path / "stats.json"
    result = run(args + ["--stats", str(stats)], tmp_path)
    assert result.returncode == 0, result.stderr
    assert "relative error of the lit sensors: median" in result.stdout, result.stdout
    # Their stage is named above the progress bar, not left as the solve's last percent.
    assert "sensors: 3 x 512 hemisphere rays over 3 frames" in result.stdout, result.stdout
    frames = read_sensor_series(tmp_path)
    assert len(frames) == 3
    for _, sensors in frames:
        data = sensors.GetPointData()
        assert data.GetArray("IrradianceStdError").GetNumberOfComponents() == 3
        assert data.GetArray("IlluminanceStdError").GetNumberOfComponents() == 1
        error = array(sensors, "IrradianceStdError")
        lux = array(sensors, "IlluminanceStdError")
        assert error.shape == (3, 3) and lux.shape == (3,)
        assert numpy.all(numpy.isfinite(error)) and numpy.all(error > 0)
        assert numpy.all(error < 0.5 * array(sensors, "Irradiance"))
        efficacy = sensors.GetFieldData().GetArray("LuminousEfficacy").GetValue(0)
        assert lux == pytest.approx(efficacy * (error @ [0.2126, 0.7152, 0.0722]), rel=1e-5)
    assert json.loads(stats.read_text())["sensors"]["rays"] == 512
    figures = json.loads(stats.read_text())["sensors"]["errorEstimate"]
    assert len(figures["relativeErrorMedian"]) == 3
    assert figures["litSensors"] == [3, 3, 3]
    # Each frame's file has its own figures, not every frame's.
    for frame, (_, sensors) in enumerate(frames):
        fields = sensors.GetFieldData()
        assert fields.GetArray("SensorRelativeErrorP95").GetNumberOfTuples() == 1
        assert fields.GetArray("SensorRelativeErrorP95").GetValue(0) == pytest.approx(
            figures["relativeErrorP95"][frame])
        assert fields.GetArray("LitSensors").GetValue(0) == 3
    for median, p95 in zip(figures["relativeErrorMedian"], figures["relativeErrorP95"]):
        assert 0 < median <= p95 < 0.5
    result = run(args + ["--error-batches", "1", "--stats", str(stats)], tmp_path)
    assert result.returncode == 0, result.stderr
    assert "relative error of the lit sensors" not in result.stdout
    data = read_sensor_series(tmp_path)[0][1].GetPointData()
    assert data.GetArray("IrradianceStdError") is None
    assert data.GetArray("IlluminanceStdError") is None
    assert "errorEstimate" not in json.loads(stats.read_text())["sensors"]


@pytest.mark.parametrize("extra,status,words", [
    (["--work-plane", "0.8"], 2, "HEIGHT,SPACING"),
    (["--work-plane", "0.8,0"], 2, "spacing above 0"),
    (["--work-plane", "0.8,0.5", "--sensors", "s.vtp"], 2, "give one of them"),
    (["--da-threshold", "300"], 2, "--da-threshold is for the sensors"),
    (["--work-plane", "0.8,1e-7"], 2, "over the maximum"),
    # Refused before the grid is built (it took 2.5 times the limit, then blamed the frames).
    (["--work-plane", "0.8,0.001", "--memory-limit", "100"], 2,
     "the work plane needs an estimated"),
    (["--work-plane", "0.8,0.01", "--memory-limit", "100"], 1,
     "use fewer sensors (a coarser grid) or fewer sensor rays"),
    (["--sensor-rays", "64"], 2, "--sensor-rays is for the sensors"),
    (["--work-plane", "0.8,0.5", "--sensor-rays", "0"], 2,
     "--sensor-rays is 0: give a value from 16 to 1000000"),
    (["--work-plane", "0.8,0.5", "--sensor-rays", "15"], 2,
     "--sensor-rays is 15: give a value from 16 to 1000000"),
])
def test_bad_sensor_options(tmp_path, extra, status, words):
    result = run(["--scene", write_room(tmp_path), "--sky", "uniform"] + extra + FAST, tmp_path)
    assert result.returncode == status, result.stderr
    assert words in result.stderr, result.stderr


def test_bad_sensor_inputs(tmp_path):
    base = ["--scene", write_room(tmp_path), "--sky", "uniform"] + FAST
    no_normals = write_sensors(tmp_path, [(1, 1, 1)], None, "bare.vtp")
    result = run(base + ["--sensors", no_normals], tmp_path)
    assert result.returncode == 1 and "no point array Normals" in result.stderr, result.stderr
    zero = write_sensors(tmp_path, [(1, 1, 1), (1, 1, 1)], [(0, 0, 1), (0, 0, 0)], "zero.vtp")
    result = run(base + ["--sensors", zero], tmp_path)
    assert result.returncode == 1 and "sensor 1 has a zero" in result.stderr, result.stderr
    result = run(["--scene", write_wall(tmp_path), "--sky", "uniform", "--work-plane", "0.8,0.5"]
                 + FAST, tmp_path)
    assert result.returncode == 1 and "no polygon facing up" in result.stderr, result.stderr


def test_a_run_without_sensors_removes_the_earlier_sensors_series(tmp_path):
    """Its frames and pictures were replaced, not its sensors' series: a run without
    sensors left the earlier one beside the new frames. A file of that name that is no
    sensors' series of the command line's stays."""
    base = ["--scene", write_room(tmp_path, ceiling=True), "--light", write_lamp(tmp_path),
            "--from", "1.5,1,2.4", "--to", "1,0.8,2.4", "--output", "out/room.pvd"] + FAST
    result = run(base + ["--frames", "3", "--work-plane", f"{HEIGHT},{SPACING}"], tmp_path)
    assert result.returncode == 0, result.stderr
    assert len(read_sensor_series(tmp_path)) == 3
    result = run(base + ["--frames", "2"], tmp_path)
    assert result.returncode == 0, result.stderr
    assert sorted(os.listdir(tmp_path / "out")) == ["room.pvd", "room_0000.vtu", "room_0001.vtu"]

    # Not the command line's: another series' frames, or no collection at all.
    mine = '<VTKFile type="Collection"><Collection><DataSet file="mine_0000.vtu"/></Collection>' \
        '</VTKFile>\n'
    (tmp_path / "out" / "room_sensors.pvd").write_text(mine)
    result = run(base + ["--frames", "2"], tmp_path)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "out" / "room_sensors.pvd").read_text() == mine


def write_outward_box(directory):
    """The room of write_room with a ceiling, modelled as a closed box with its normals
    outward: its floor faces down, its roof up."""
    room = Polygons()
    room.add([(0, 0, 0), (0, D, 0), (W, D, 0), (W, 0, 0)])          # floor, facing down
    room.add([(0, 0, H), (W, 0, H), (W, D, H), (0, D, H)])          # roof, facing up
    room.add([(0, 0, 0), (0, 0, H), (0, D, H), (0, D, 0)])          # x = 0, facing -x
    room.add([(W, 0, 0), (W, D, 0), (W, D, H), (W, 0, H)])          # x = W, facing +x
    room.add([(0, 0, 0), (W, 0, 0), (W, 0, H), (0, 0, H)])          # y = 0, facing -y
    room.add([(0, D, 0), (0, D, H), (W, D, H), (W, D, 0)])          # y = D, facing +y
    return room.write(directory / "outward.vtp")


def test_work_plane_finds_the_floor_of_a_room_with_outward_normals(tmp_path):
    """The solve is two-sided: a room modelled with outward normals is lit as the same room
    with inward ones. Its work plane was 0.8 above its roof, outside, at 0 lx: it is the same
    grid over its floor, which sees the lamp."""
    lamp = ["--point-light", "--from", "1.5,1,2.4", "--to", "1,0.8,2.4", "--frames", "2",
            "--work-plane", f"{HEIGHT},{SPACING}"] + FAST
    result = run(["--scene", write_outward_box(tmp_path), "--output", "out/room.pvd"] + lamp,
                 tmp_path)
    assert result.returncode == 0, result.stderr
    assert "--work-plane" not in result.stderr, result.stderr
    outward = read_sensor_series(tmp_path)
    result = run(["--scene", write_room(tmp_path, ceiling=True), "--output", "in/room.pvd"] + lamp,
                 tmp_path)
    assert result.returncode == 0, result.stderr
    inward = read_sensor_series(tmp_path, "in/room_sensors.pvd")
    for (_, a), (_, b) in zip(outward, inward):
        assert a.GetNumberOfPoints() == b.GetNumberOfPoints() == 24
        assert vtk_to_numpy(a.GetPoints().GetData()) == pytest.approx(
            vtk_to_numpy(b.GetPoints().GetData()), abs=1e-12)
        assert numpy.allclose(array(a, "Normals"), [0, 0, 1])
        assert numpy.all(array(a, "Illuminance") > 0)


def write_windowed_room(directory, outward, ground=None, rooms=(), blocks=()):
    """The room of write_room closed by a ceiling, with a 1 x 1 window (x in [1, 2], z in
    [1, 2]) in its wall y = 0, its normals inward or outward; with `ground`, on a ground
    (GROUND, facing up) at that height; with closed `rooms` (x0, x1, y0, y1, z0, z1) whose
    normals face like the room's, and `blocks` whose normals face outward."""
    room = Polygons()
    if ground is not None:
        x0, x1, y0, y1 = GROUND
        room.add([(x0, y0, ground), (x1, y0, ground), (x1, y1, ground), (x0, y1, ground)])
    for bounds in rooms:
        add_block(room, *bounds, inward=not outward)
    for bounds in blocks:
        add_block(room, *bounds)

    def add(inward_corners):
        room.add(inward_corners[::-1] if outward else inward_corners)

    add([(0, 0, 0), (W, 0, 0), (W, D, 0), (0, D, 0)])              # floor
    add([(0, 0, H), (0, D, H), (W, D, H), (W, 0, H)])              # ceiling
    add([(0, 0, 0), (0, D, 0), (0, D, H), (0, 0, H)])              # x = 0
    add([(W, 0, 0), (W, 0, H), (W, D, H), (W, D, 0)])              # x = W
    add([(0, D, 0), (W, D, 0), (W, D, H), (0, D, H)])              # y = D
    for x0, x1, z0, z1 in ((0, 1, 0, H), (2, W, 0, H), (1, 2, 0, 1), (1, 2, 2, H)):
        add([(x0, 0, z0), (x0, 0, z1), (x1, 0, z1), (x1, 0, z0)])  # y = 0, around the window
    return room.write(directory / ("outward.vtp" if outward else "inward.vtp"))


@pytest.mark.parametrize("daylight", ["sky", "sun"])
def test_work_plane_under_daylight_does_not_depend_on_the_normals(tmp_path, daylight):
    """The solve is two-sided, so a room with a window modelled with outward normals is lit
    as the same room with inward ones, under the sky as under the sun through its window.
    Under daylight its work plane was 0.8 above its roof, in full daylight (polygons facing
    down were not looked at): it is the same grid over its floor, with the same illuminance
    within the noise."""
    light = (["--sky", "uniform", "--sky-diffuse-horizontal", str(EDH)] if daylight == "sky"
             else ["--sun-directions",
                   write_points(tmp_path / "sun.vtp", [(0, -1, 1), (0.3, -1, 0.8)])])
    frames = {}
    for outward in (False, True):
        name = "outward" if outward else "inward"
        result = run(["--scene", write_windowed_room(tmp_path, outward), "--work-plane",
                      f"{HEIGHT},{SPACING}", "--output", f"{name}/room.pvd", "--paths", "200000",
                      "--threads", "2", "--patch-size", "0.25"] + light, tmp_path)
        assert result.returncode == 0, result.stderr
        assert "--work-plane" not in result.stderr, result.stderr
        frames[name] = read_sensor_series(tmp_path, f"{name}/room_sensors.pvd")
    assert len(frames["inward"]) == len(frames["outward"]) == (1 if daylight == "sky" else 2)
    for (_, inward), (_, outward) in zip(frames["inward"], frames["outward"]):
        assert inward.GetNumberOfPoints() == outward.GetNumberOfPoints() == 24
        points = vtk_to_numpy(outward.GetPoints().GetData())
        assert points == pytest.approx(vtk_to_numpy(inward.GetPoints().GetData()), abs=1e-12)
        assert numpy.allclose(points[:, 2], HEIGHT)
        a, b = array(inward, "Illuminance"), array(outward, "Illuminance")
        sigma = numpy.hypot(array(inward, "IlluminanceStdError"),
                            array(outward, "IlluminanceStdError"))
        assert numpy.all(a > 0) and numpy.all(b > 0)
        assert numpy.all(numpy.abs(a - b) <= 5 * sigma + 1e-6 * a), numpy.abs(a - b) / sigma


def lattice(x0, x1, y0, y1, z):
    """--work-plane's points over [x0, x1] x [y0, y1] at height z, for bounds on its lattice
    (multiples of SPACING): (i + 1/2) SPACING along x and y."""
    xs = numpy.arange(x0 + SPACING / 2, x1, SPACING)
    ys = numpy.arange(y0 + SPACING / 2, y1, SPACING)
    return [(x, y, z) for x in xs for y in ys]


def keys(points):
    return sorted(tuple(numpy.round(p, 6)) for p in points)


def same_illuminance(a, b, lit=True):
    """Each of `a`'s sensors has the illuminance of `b`'s sensor at its point (the first, if
    several) within 5 standard errors; both lit, unless not `lit`."""
    first = {}
    for i, p in enumerate(vtk_to_numpy(b.GetPoints().GetData())):
        first.setdefault(tuple(numpy.round(p, 6)), i)
    at = [first[tuple(numpy.round(p, 6))] for p in vtk_to_numpy(a.GetPoints().GetData())]
    la, lb = array(a, "Illuminance"), array(b, "Illuminance")[at]
    sigma = numpy.hypot(array(a, "IlluminanceStdError"), array(b, "IlluminanceStdError")[at])
    assert not lit or (numpy.all(la > 0) and numpy.all(lb > 0))
    assert numpy.all(numpy.abs(la - lb) <= 5 * sigma + 1e-6 * lb), numpy.abs(la - lb) / sigma


SOLVE = ["--paths", "200000", "--threads", "2", "--patch-size", "0.25"]
DAYLIGHT = ["--sky", "uniform", "--sky-diffuse-horizontal", str(EDH)] + SOLVE


@pytest.mark.parametrize("ground", [-0.01, 0.0, -1.5])
def test_work_plane_finds_the_floor_of_an_outward_room_on_a_ground(tmp_path, ground):
    """The windowed room with outward normals on a ground facing up: just under its floor, at
    its level, or 1.5 below it (on stilts). A ground under the floor made the floor a ceiling
    over its floor (a polygon facing up at it straight below): the room's sensors stayed 0.8
    above its roof in full daylight, without a warning; at the floor's level the ground's
    sensors under the room doubled the floor's. Its grid is that of the same room with inward
    normals, 24 sensors 0.8 above the floor with the same illuminance within the noise, and
    the ground's outside the room; none above the roof. The ground's sensors under the room go
    when the floor lies between the ground and them (they are in the room, whose grid covers
    them); 1.5 below they stay, outdoors under the room."""
    frames = {}
    for outward in (False, True):
        name = "outward" if outward else "inward"
        result = run(["--scene", write_windowed_room(tmp_path, outward, ground), "--work-plane",
                      f"{HEIGHT},{SPACING}", "--output", f"{name}/room.pvd"] + DAYLIGHT, tmp_path)
        assert result.returncode == 0, result.stderr
        assert "--work-plane" not in result.stderr, result.stderr
        frames[name] = read_sensor_series(tmp_path, f"{name}/room_sensors.pvd")[0][1]
    room = lattice(0, W, 0, D, HEIGHT)
    outdoors = lattice(*GROUND, ground + HEIGHT)
    # The polygons facing up alone: the floor's grid, and the ground's all over.
    assert keys(vtk_to_numpy(frames["inward"].GetPoints().GetData())) == keys(room + outdoors)
    if -ground < HEIGHT:
        outdoors = [p for p in outdoors if not (0 < p[0] < W and 0 < p[1] < D)]
    points = vtk_to_numpy(frames["outward"].GetPoints().GetData())
    assert numpy.all(points[:, 2] < H)
    assert keys(points) == keys(room + outdoors)
    same_illuminance(frames["outward"], frames["inward"])


def add_block(polygons, x0, x1, y0, y1, z0, z1, inward=False):
    """A closed block, its normals outward (or inward: a closed room)."""
    for corners in ([(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],   # bottom
                    [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],   # top
                    [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)],   # x = x0
                    [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],   # x = x1
                    [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],   # y = y0
                    [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)]):  # y = y1
        polygons.add(corners[::-1] if inward else corners)


def write_room_with_a_roof_opening(directory, outward):
    """The room of write_room closed by a ceiling with a 1 x 1 opening (x in [1, 2], y in
    [0.5, 1.5]) over a table (a block 0.75 high standing on the floor, x in [1.1, 1.9], y in
    [0.6, 1.4]), and a parapet 1.1 high and 0.1 thick round its top; the room's normals inward
    or outward, the blocks' outward."""
    room = Polygons()

    def add(inward_corners):
        room.add(inward_corners[::-1] if outward else inward_corners)

    add([(0, 0, 0), (W, 0, 0), (W, D, 0), (0, D, 0)])              # floor
    for x0, x1, y0, y1 in ((0, W, 0, 0.5), (0, W, 1.5, D), (0, 1, 0.5, 1.5), (2, W, 0.5, 1.5)):
        add([(x0, y0, H), (x0, y1, H), (x1, y1, H), (x1, y0, H)])  # ceiling, around the opening
    add([(0, 0, 0), (0, D, 0), (0, D, H), (0, 0, H)])              # x = 0
    add([(W, 0, 0), (W, 0, H), (W, D, H), (W, D, 0)])              # x = W
    add([(0, 0, 0), (0, 0, H), (W, 0, H), (W, 0, 0)])              # y = 0
    add([(0, D, 0), (W, D, 0), (W, D, H), (0, D, H)])              # y = D
    add_block(room, 1.1, 1.9, 0.6, 1.4, 0, 0.75)
    for x0, x1, y0, y1 in ((0, W, 0, 0.1), (0, W, D - 0.1, D), (0, 0.1, 0.1, D - 0.1),
                           (W - 0.1, W, 0.1, D - 0.1)):
        add_block(room, x0, x1, y0, y1, H, H + 1.1)
    return room.write(directory / ("outward.vtp" if outward else "inward.vtp"))


@pytest.mark.parametrize("daylight", ["sky", "sun"])
def test_work_plane_keeps_a_table_under_an_opening_of_an_outward_room(tmp_path, daylight):
    """A table with the sky straight above it, through an opening in the roof of a room with
    outward normals, was taken for a roof (nothing above it) over the room's floor, and lost
    its sensors. It stands within the room's walls, seen from inside (from behind), where a
    roof stands on them, its parapet seen from outside: the grid is that of the same room with
    inward normals, the floor's 24 sensors and the table's 4 at 0.75 + 0.8, with the same
    illuminance within the noise; the roof's go."""
    # The sun through the opening onto the table, from two directions.
    sun = write_points(tmp_path / "sun.vtp", [(0.1, 0.05, 1), (-0.1, 0, 1)])
    # More rays per sensor than the default 512: the table sees the sky through a small opening.
    light = (DAYLIGHT if daylight == "sky" else ["--sun-directions", sun] + SOLVE) + [
        "--sensor-rays", "4096"]
    frames = {}
    for outward in (False, True):
        name = "outward" if outward else "inward"
        result = run(["--scene", write_room_with_a_roof_opening(tmp_path, outward),
                      "--work-plane", f"{HEIGHT},{SPACING}", "--output", f"{name}/room.pvd"]
                     + light, tmp_path)
        assert result.returncode == 0, result.stderr
        assert "--work-plane" not in result.stderr, result.stderr
        frames[name] = read_sensor_series(tmp_path, f"{name}/room_sensors.pvd")
    table = lattice(1.0, 2.0, 0.5, 1.5, 0.75 + HEIGHT)
    expected = keys(lattice(0, W, 0, D, HEIGHT) + table)
    assert len(frames["inward"]) == len(frames["outward"]) == (1 if daylight == "sky" else 2)
    for (_, inward), (_, outward) in zip(frames["inward"], frames["outward"]):
        assert keys(vtk_to_numpy(inward.GetPoints().GetData())) == expected
        assert keys(vtk_to_numpy(outward.GetPoints().GetData())) == expected
        same_illuminance(outward, inward)


@pytest.mark.parametrize("neighbour", ["unit", "bench"])
def test_work_plane_of_an_outward_room_and_a_neighbour_touching_it(tmp_path, neighbour):
    """The windowed room on a ground at -0.01, with a closed block touching it and standing on
    the ground like it: a windowless unit of a terrace sharing its wall x = W (3 x 2, as high
    as the room, its normals like the room's), or a bench at its corner (W, D) (1 x 1, 0.45
    high, its normals outward; at a corner, as a block against a wall lit the room with
    inward normals through the faces they share).
    With outward normals the bottoms touching at one height are one floor, found by the room's
    window: the unit's floor, dark, is a floor, as it is with inward normals. So was the
    bench's bottom: its 4 sensors stood 0.8 above the bottom, not 0.8 above its top, and the
    ground's beneath it went. A solid lower than the work plane holds none, and is left as with
    inward normals: the grid is that of the room and unit with inward normals but for the
    ground's sensors under them (in them), with the same illuminance within the noise."""
    rooms, blocks = ([(W, 2 * W, 0, D, 0, H)], []) if neighbour == "unit" else (
        [], [(W, W + 1, D, D + 1, 0, 0.45)])
    frames = {}
    for outward in (False, True):
        name = "outward" if outward else "inward"
        result = run(["--scene", write_windowed_room(tmp_path, outward, -0.01, rooms, blocks),
                      "--work-plane", f"{HEIGHT},{SPACING}", "--output", f"{name}/room.pvd"]
                     + DAYLIGHT, tmp_path)
        assert result.returncode == 0, result.stderr
        assert "--work-plane" not in result.stderr, result.stderr
        frames[name] = read_sensor_series(tmp_path, f"{name}/room_sensors.pvd")[0][1]
    x1 = 2 * W if neighbour == "unit" else W
    inward = vtk_to_numpy(frames["inward"].GetPoints().GetData())
    # The ground's sensors under the room (and the unit).
    x, y, z = inward.T
    under = (numpy.abs(z - (HEIGHT - 0.01)) < 1e-9) & (0 < x) & (x < x1) & (0 < y) & (y < D)
    assert keys(inward[under]) == keys(
        p for p in lattice(*GROUND, HEIGHT - 0.01) if 0 < p[0] < x1 and 0 < p[1] < D)
    if neighbour == "bench":
        assert keys(inward[inward[:, 2] > HEIGHT]) == keys(
            lattice(W, W + 1, D, D + 1, 0.45 + HEIGHT))
    assert keys(vtk_to_numpy(frames["outward"].GetPoints().GetData())) == keys(inward[~under])
    # The unit, closed, is dark.
    same_illuminance(frames["outward"], frames["inward"], lit=neighbour == "bench")


def test_work_plane_follows_up(tmp_path):
    # The same 3 x 2 floor in the x-z plane, facing +y, with --up 0,1,0: 24 sensors 0.8 above
    # it along y, facing +y; a ceiling-like face (facing -y) gets none.
    floor = Polygons().add([(0, 0, 0), (0, 0, D), (W, 0, D), (W, 0, 0)])
    floor.add([(0, 3, 0), (W, 3, 0), (W, 3, D), (0, 3, D)])
    result = run(["--scene", floor.write(tmp_path / "floor.vtp"), "--sky", "uniform",
                  "--up", "0,1,0", "--work-plane", f"{HEIGHT},{SPACING}",
                  "--output", "out/room.pvd"] + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    sensors = read_sensor_series(tmp_path)[0][1]
    assert sensors.GetNumberOfPoints() == 24
    points = vtk_to_numpy(sensors.GetPoints().GetData())
    assert numpy.allclose(points[:, 1], HEIGHT)
    assert numpy.allclose(array(sensors, "Normals"), [0, 1, 0])
    assert numpy.all((points[:, 0] > 0) & (points[:, 0] < W) & (points[:, 2] > 0) & (points[:, 2] < D))

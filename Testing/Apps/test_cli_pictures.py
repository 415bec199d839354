"""The command line's pictures (--png) are the filter's display: each pixel of a surface is its
frame's point array Color as the series holds it, and the lamps are drawn where the filter
posed them in that frame, a turning lamp turned and every lamp of a rig at its own place.

The scene is a wall at z = 1 facing the camera (which looks along +z from the -z side and
frames the front of the scene's bounding box, here the wall); two bar-shaped lamps between them
face the wall. Lamp 0 stays in place and turns a quarter turn about the view axis; lamp 1 moves
without turning. The pixels are compared with the frames through the camera's projection.

ctest sets MLR_CLI and MLR_DATA_DIR; by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps
"""
import math
import os
import shutil
import sys
import xml.etree.ElementTree as ElementTree

import numpy
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from cli_support import LIGHT, SCENE, run, write_polydata  # noqa: E402
from test_cli_rigs_and_sun import Polygons, square_z, write_points  # noqa: E402

from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkFiltersCore import vtkProbeFilter
from vtkmodules.vtkIOImage import vtkPNGReader
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader
from vtkmodules.vtkRenderingCore import vtkCamera

pytestmark = pytest.mark.skipif(shutil.which("Xvfb") is None and not os.environ.get("DISPLAY"),
                                reason="pictures need Xvfb or a display")

SIZE = 640                 # the pictures' width and height
VIEW_ANGLE = 39.3          # degrees, the Cornell box camera's
LAMP_COLOR = (255, 217, 51)  # the plugin's Light representation, (1, 0.85, 0.2)
WALL_Z = 1.0
WALL_HALF = 1.0
LAMP_Z = 0.5
BAR_HALF_LENGTH, BAR_HALF_WIDTH = 0.25, 0.03
QUARTER_TURN_Z = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))  # w, x, y, z
# Per lamp, per frame: centroid and whether it is turned a quarter turn about z.
POSES = [[((-0.45, 0.3, LAMP_Z), False), ((-0.45, 0.3, LAMP_Z), True)],
         [((0.25, -0.5, LAMP_Z), False), ((0.55, 0.05, LAMP_Z), False)]]


def bar(centre, turned=False):
    """The lamp's corners, facing +z (the wall): long along x, or along y when turned."""
    x, y, z = centre
    a, b = (BAR_HALF_WIDTH, BAR_HALF_LENGTH) if turned else (BAR_HALF_LENGTH, BAR_HALF_WIDTH)
    return [(x - a, y - b, z), (x + a, y - b, z), (x + a, y + b, z), (x - a, y + b, z)]


@pytest.fixture(scope="module")
def pictures(tmp_path_factory):
    """[(frame grid, picture)] of a two-frame run, the picture as SIZE x SIZE x 3, row 0 at
    the bottom."""
    directory = tmp_path_factory.mktemp("pictures")
    wall = Polygons().add(square_z((0, 0, WALL_Z), WALL_HALF, up=False))
    lamps = Polygons()
    for i, frames in enumerate(POSES):
        lamps.add(bar(frames[0][0]), LightId=i)
    path = write_points(directory / "path.vtp", [pose for frames in POSES for pose, _ in frames],
                        lines=[[0, 1], [2, 3]],
                        Orientation=[QUARTER_TURN_Z if turned else (1.0, 0.0, 0.0, 0.0)
                                     for frames in POSES for _, turned in frames])
    result = run(["--scene", wall.write(directory / "wall.vtp"),
                  "--light", lamps.write(directory / "lamps.vtp"), "--trajectory", path,
                  "--output", "out/s.pvd", "--png", "png", "--paths", "20000",
                  "--patch-size", "0.1", "--threads", "2"], directory)
    assert result.returncode == 0, result.stderr
    frames = []
    for k, dataset in enumerate(ElementTree.parse(directory / "out" / "s.pvd")
                                .findall(".//DataSet")):
        reader = vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(directory / "out" / dataset.get("file")))
        reader.Update()
        png = vtkPNGReader()
        png.SetFileName(str(directory / "png" / f"s_000{k}.png"))
        png.Update()
        image = png.GetOutput()
        assert image.GetDimensions()[:2] == (SIZE, SIZE)
        pixels = vtk_to_numpy(image.GetPointData().GetScalars())[:, :3].reshape(SIZE, SIZE, 3)
        frames.append((reader.GetOutput(), pixels.astype(int)))
    assert len(frames) == 2
    return frames


def camera_matrix():
    """World to normalised device coordinates, for the camera that frames the wall."""
    distance = WALL_HALF / math.tan(math.radians(VIEW_ANGLE / 2))
    camera = vtkCamera()
    camera.SetFocalPoint(0, 0, WALL_Z)
    camera.SetPosition(0, 0, WALL_Z - distance)
    camera.SetViewUp(0, 1, 0)
    camera.SetViewAngle(VIEW_ANGLE)
    m = camera.GetCompositeProjectionTransformMatrix(1.0, -1, 1)
    return numpy.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])


def pixel_of(point):
    """(row, column) of the pixel that sees `point`."""
    ndc = camera_matrix() @ numpy.append(point, 1.0)
    x, y = ndc[:2] / ndc[3]
    return int((y + 1) / 2 * SIZE), int((x + 1) / 2 * SIZE)


def seen_on_wall(rows, columns):
    """The points of the wall seen through the centres of pixels (rows, columns)."""
    inverse = numpy.linalg.inv(camera_matrix())
    ndc = numpy.stack([(columns + 0.5) / SIZE * 2 - 1, (rows + 0.5) / SIZE * 2 - 1], axis=-1)
    ends = []
    for depth in (-1.0, 1.0):
        h = numpy.concatenate([ndc, numpy.full((len(ndc), 1), depth), numpy.ones((len(ndc), 1))],
                              axis=1) @ inverse.T
        ends.append(h[:, :3] / h[:, 3:])
    t = (WALL_Z - ends[0][:, 2]) / (ends[1][:, 2] - ends[0][:, 2])
    on_wall = ends[0] + t[:, None] * (ends[1] - ends[0])
    on_wall[:, 2] = WALL_Z  # exactly: VTK's probe misses a triangle from 1e-16 below it
    return on_wall, ends


def lamp_axis(centre, turned):
    return numpy.array((0.0, 1.0, 0.0) if turned else (1.0, 0.0, 0.0))


def is_lamp(pixel):
    return numpy.abs(pixel - LAMP_COLOR).max() <= 3


def test_lamps_are_drawn_where_the_filter_poses_them(pictures):
    for k, (grid, picture) in enumerate(pictures):
        # The filter's own record of the first lamp's centroid in this frame.
        position = grid.GetFieldData().GetArray("LightPosition").GetTuple(0)
        assert position == pytest.approx(POSES[0][k][0])
        for frames in POSES:
            centre, turned = frames[k]
            axis = lamp_axis(centre, turned)
            for f in (-0.8, -0.4, 0.0, 0.4, 0.8):
                row, column = pixel_of(numpy.array(centre) + f * BAR_HALF_LENGTH * axis)
                assert is_lamp(picture[row, column]), (k, centre, f, picture[row, column])
            # Where this lamp is in the other frame and not in this one, the wall shows.
            other_centre, other_turned = frames[1 - k]
            other_axis = lamp_axis(other_centre, other_turned)
            for f in (-0.8, 0.8):
                point = numpy.array(other_centre) + f * BAR_HALF_LENGTH * other_axis
                along = abs((point - centre) @ axis)
                across = numpy.linalg.norm((point - centre) - ((point - centre) @ axis) * axis)
                if along < BAR_HALF_LENGTH + 0.05 and across < BAR_HALF_WIDTH + 0.05:
                    continue  # still under this frame's lamp
                row, column = pixel_of(point)
                assert not is_lamp(picture[row, column]), (k, other_centre, f)


def test_pixels_are_the_frames_point_colours(pictures):
    step = 3
    rows, columns = numpy.meshgrid(numpy.arange(0, SIZE, step), numpy.arange(0, SIZE, step),
                                   indexing="ij")
    rows, columns = rows.ravel(), columns.ravel()
    on_wall, (near, far) = seen_on_wall(rows, columns)
    for k, (grid, picture) in enumerate(pictures):
        # Inside the wall, away from its edge (a few pixels of antialiasing) and from the rays
        # that pass a lamp on their way.
        keep = numpy.abs(on_wall[:, :2]).max(axis=1) < WALL_HALF - 0.02
        at_lamps = near + ((LAMP_Z - near[:, 2]) / (far[:, 2] - near[:, 2]))[:, None] * (far - near)
        for frames in POSES:
            centre, turned = frames[k]
            half = numpy.array((BAR_HALF_WIDTH, BAR_HALF_LENGTH) if turned
                               else (BAR_HALF_LENGTH, BAR_HALF_WIDTH))
            keep &= (numpy.abs(at_lamps[:, :2] - centre[:2]) > half + 0.02).any(axis=1)
        assert keep.sum() > 10000

        # The frame's point Color, interpolated linearly over its triangles (the wall faces
        # the camera, so perspective does not bend the interpolation).
        colours = grid.GetPointData().GetArray("Color")
        assert colours is not None and colours.GetNumberOfComponents() == 3
        probed_grid = grid.NewInstance()
        probed_grid.ShallowCopy(grid)
        floats = numpy_to_vtk(vtk_to_numpy(colours).astype(float), deep=True)
        floats.SetName("ColorValues")
        probed_grid.GetPointData().AddArray(floats)
        points = vtkPoints()
        points.SetData(numpy_to_vtk(on_wall[keep], deep=True))
        probes = vtkPolyData()
        probes.SetPoints(points)
        probe = vtkProbeFilter()
        probe.SetInputData(probes)
        probe.SetSourceData(probed_grid)
        probe.Update()
        output = probe.GetOutput().GetPointData()
        assert vtk_to_numpy(output.GetArray("vtkValidPointMask")).all()
        expected = vtk_to_numpy(output.GetArray("ColorValues"))
        seen = picture[rows[keep], columns[keep]]
        difference = numpy.abs(seen - expected)
        # The wall is lit unevenly: the comparison covers many colours.
        assert numpy.ptp(expected[:, 1]) > 60, k
        assert difference.max() <= 2, (k, difference.max(), numpy.argmax(difference.max(axis=1)))


def picture_pixels(path):
    png = vtkPNGReader()
    png.SetFileName(str(path))
    png.Update()
    return vtk_to_numpy(png.GetOutput().GetPointData().GetScalars())[:, :3].astype(float)


def share(pixels, channel, factor=1.5):
    """The share of the pixels whose `channel` is `factor` times each of the other two."""
    others = [c for c in range(3) if c != channel]
    main = pixels[:, channel]
    return float(numpy.mean((main > factor * pixels[:, others[0]]) &
                            (main > factor * pixels[:, others[1]])))


def test_a_closed_room_is_seen_from_inside(tmp_path):
    """The Cornell box closed by a blue front wall (its normal into the room), the lamp inside.
    From outside the picture is that wall, coloured by the light of its inner side; the
    camera goes inside, near that wall, and sees the red and green walls. The open box keeps
    the outside camera."""
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(SCENE)
    reader.Update()
    open_box = reader.GetOutput()
    write_polydata(open_box, tmp_path / "open.vtp")
    closed = vtkPolyData()
    closed.DeepCopy(open_box)
    x1, y1 = closed.GetBounds()[1], closed.GetBounds()[3]
    ids = [closed.GetPoints().InsertNextPoint(*corner)
           for corner in ((0, 0, 0), (x1, 0, 0), (x1, y1, 0), (0, y1, 0))]
    closed.GetPolys().InsertNextCell(4, ids)
    closed.GetCellData().GetArray("Reflectance").InsertNextTuple((0.1, 0.1, 0.6))
    write_polydata(closed, tmp_path / "closed.vtp")
    common = ["--light", LIGHT, "--from", "0.2,0.5478,0.25", "--to", "0.3,0.5478,0.3",
              "--frames", "2", "--paths", "20000", "--patch-size", "0.08"]
    result = run(["--scene", "closed.vtp", "--output", "c/s.pvd", "--png", "c-png"] + common,
                 tmp_path)
    assert result.returncode == 0, result.stderr
    for k in range(2):
        pixels = picture_pixels(tmp_path / "c-png" / f"s_000{k}.png")
        assert share(pixels, 2) < 0.1, k        # the blue wall, behind the camera
        assert share(pixels, 0) > 0.04, k       # the red wall
        assert share(pixels, 1, 1.3) > 0.04, k  # the green wall
        assert pixels.mean() > 100, k           # lit walls, not the dark outside
    assert "pictures from inside the scene, at (0.278, 0.274, " in result.stdout

    result = run(["--scene", "open.vtp", "--output", "o/s.pvd", "--png", "o-png"] + common,
                 tmp_path)
    assert result.returncode == 0, result.stderr
    assert "pictures from inside" not in result.stdout

"""Scene files with materials on the command line: the Cornell box OBJ+MTL of Data/
brings its colours and its lamp, and --light-material moves the lamp.

ctest sets MLR_CLI and MLR_DATA_DIR; by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps/test_cli_materials.py
"""
import json
import math
import os
import shutil
import sys

import numpy
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from cli_support import DATA, all_files, run  # noqa: E402

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersVerdict import vtkCellSizeFilter
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

OBJ = os.path.join(DATA, "CornellBox-Original.obj")
# The lamp (material 'light', Ke 17 12 4) under the ceiling at y = 1.98, moved 0.3 to the side.
PATH = ["--from", "-0.15,1.97,-0.1", "--to", "0.15,1.97,0.1", "--frames", "3"]
FAST = ["--paths", "60000", "--threads", "2"]


def frame(directory, index):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(directory / "out" / f"cornell_{index:04d}.vtu"))
    sizes = vtkCellSizeFilter()
    sizes.SetInputConnection(reader.GetOutputPort())
    sizes.Update()
    return sizes.GetOutput()


def copy_scene(tmp_path):
    for name in ("CornellBox-Original.obj", "CornellBox-Original.mtl"):
        shutil.copy(os.path.join(DATA, name), tmp_path / name)
    return str(tmp_path / "CornellBox-Original.obj")


def test_light_material_is_the_moving_lamp_with_its_own_power(tmp_path):
    result = run(["--scene", OBJ, "--light-material", "light", "--output", "out/cornell.pvd",
                  "--stats", "out/stats.json"] + PATH + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    stats = json.loads((tmp_path / "out" / "stats.json").read_text())
    assert stats["light"] == "material light"
    # The power solved is the material's, pi Ke area (the Light output's Power), not
    # LightPower's 100 W, which --stats used to state.
    lighting = stats["lighting"]
    assert lighting["kind"] == "material" and lighting["material"] == "light"
    assert lighting["powerFrom"] == "the material's emission (pi Ke area)"
    power = lighting["powerW"]
    assert power == pytest.approx([9.432, 6.658, 2.219], abs=0.002)
    assert numpy.array(power) / (math.pi * numpy.array([17, 12, 4])) == pytest.approx(
        power[0] / (math.pi * 17), rel=1e-6)
    assert stats["settings"]["lightPower"] == power
    assert lighting["lumens"] == pytest.approx(
        179 * (0.2126 * power[0] + 0.7152 * power[1] + 0.0722 * power[2]))
    assert [f["lightPosition"][0] for f in stats["frames"]] == pytest.approx([-0.15, 0, 0.15])
    data = frame(tmp_path, 1)
    # The materials' Kd, not grey: the left wall red, the right wall green.
    rho = vtk_to_numpy(data.GetCellData().GetArray("Reflectance"))
    assert (abs(rho - (0.63, 0.065, 0.05)).max(axis=1) < 1e-6).any()
    assert (abs(rho - (0.14, 0.45, 0.091)).max(axis=1) < 1e-6).any()
    # The lamp left the geometry: no element carries its Kd 0.78, and nothing emits.
    assert not (abs(rho - 0.78).max(axis=1) < 1e-6).any()
    assert vtk_to_numpy(data.GetCellData().GetArray("EmittedRadiosity")).max() == 0.0
    check_first_hits_carry_the_lamp_power(data)


def check_first_hits_carry_the_lamp_power(data):
    """The lamp's power is pi Ke times its area. The box's front is open, so some of it leaves
    without a hit: the first-hit power sum A B_direct / rho is most of it (81% measured), never
    more (a lamp of a wrong power, e.g. LightPower's 100 W, fails either bound); and it comes
    in the proportions of Ke, as the same walks carry every channel."""
    rho = vtk_to_numpy(data.GetCellData().GetArray("Reflectance"))
    area = vtk_to_numpy(data.GetCellData().GetArray("Area"))
    direct = vtk_to_numpy(data.GetCellData().GetArray("DirectRadiosity"))
    hit = (area[:, None] * direct / rho).sum(axis=0)
    power = [math.pi * ke * lamp_area() for ke in (17, 12, 4)]
    for channel in range(3):
        assert 0.7 * power[channel] < hit[channel] < 1.01 * power[channel], (hit, power)
        assert abs(hit[channel] / hit[0] - power[channel] / power[0]) < 1e-4, hit


def lamp_area():
    """The area of the OBJ's 'light' faces, read from the file."""
    points, area, current = [], 0.0, None
    with open(OBJ) as obj:
        for line in obj:
            words = line.split()
            if not words:
                continue
            if words[0] == "v":
                points.append([float(w) for w in words[1:4]])
            elif words[0] == "usemtl":
                current = words[1]
            elif words[0] == "f" and current == "light":
                # 1-based, or negative: counted back from the last vertex so far.
                ids = [int(w.split("/")[0]) for w in words[1:]]
                corners = [points[i - 1] if i > 0 else points[len(points) + i] for i in ids]
                for i in range(1, len(corners) - 1):
                    a, b, c = corners[0], corners[i], corners[i + 1]
                    u = [b[k] - a[k] for k in range(3)]
                    v = [c[k] - a[k] for k in range(3)]
                    cross = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
                    area += 0.5 * math.sqrt(sum(x * x for x in cross))
    assert area > 0
    return area


def test_light_power_option_wins_over_the_material(tmp_path):
    args = ["--scene", OBJ, "--light-material", "light", "--output", "out/cornell.pvd"] + PATH + FAST
    (tmp_path / "own").mkdir()
    (tmp_path / "given").mkdir()
    own = run(args, tmp_path / "own")
    assert own.returncode == 0, own.stderr
    given = run(args + ["--light-power", "10"], tmp_path / "given")
    assert given.returncode == 0, given.stderr
    own_direct = vtk_to_numpy(frame(tmp_path / "own", 0).GetCellData().GetArray("DirectRadiosity"))
    given_direct = vtk_to_numpy(frame(tmp_path / "given", 0).GetCellData().GetArray("DirectRadiosity"))
    # Same paths, other power: channel ratios 10 / (pi Ke A).
    ratio = given_direct.sum(axis=0) / own_direct.sum(axis=0)
    expected = [10 / (math.pi * ke * lamp_area()) for ke in (17, 12, 4)]
    for got, want in zip(ratio, expected):
        assert abs(got / want - 1) < 1e-3, (ratio, expected)


def test_without_light_material_the_lamp_emits_in_place(tmp_path):
    """The lamp is an emissive material: without --light-material it stays in the scene and
    emits from its front side in every frame, with another light moving."""
    result = run(["--scene", OBJ, "--light", os.path.join(DATA, "cornell_light.vtp"),
                  "--light-power", "1", "--output", "out/cornell.pvd"] + PATH + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    emitted = vtk_to_numpy(frame(tmp_path, 0).GetCellData().GetArray("EmittedRadiosity"))
    # pi Ke on the lamp's elements.
    lamp = emitted[:, 0] > 0
    assert lamp.any()
    assert abs(emitted[lamp] - [math.pi * 17, math.pi * 12, math.pi * 4]).max() < 1e-3


def test_scene_alone_is_lit_by_its_own_lamp_in_one_frame(tmp_path):
    """--scene without a light: the lamp material (Ke) stays in place and lights the box; nothing
    moves, so the series is one frame."""
    result = run(["--scene", OBJ, "--output", "out/cornell.pvd", "--stats", "out/s.json"] + FAST,
                 tmp_path)
    assert result.returncode == 0, result.stderr
    assert all_files(tmp_path / "out") == ["cornell.pvd", "cornell_0000.vtu", "s.json"]
    stats = json.loads((tmp_path / "out" / "s.json").read_text())
    assert stats["light"] == "scene emission" and stats["statistics"]["Frames"] == 1
    data = frame(tmp_path, 0)
    emitted = vtk_to_numpy(data.GetCellData().GetArray("EmittedRadiosity"))
    lamp = emitted[:, 0] > 0
    assert lamp.any()
    assert abs(emitted[lamp] - [math.pi * 17, math.pi * 12, math.pi * 4]).max() < 1e-3
    check_first_hits_carry_the_lamp_power(data)


def test_scene_alone_that_emits_nothing_is_refused(tmp_path):
    result = run(["--scene", os.path.join(DATA, "cornell_box.vtp"), "--output", "out/c.pvd"],
                 tmp_path)
    assert result.returncode == 2
    assert "--scene needs --light FILE or --light-material NAME, or surfaces that emit" in \
        result.stderr and "emits nothing" in result.stderr, result.stderr
    assert all_files(tmp_path) == []
    result = run(["--scene", OBJ, "--output", "out/c.pvd"] + PATH, tmp_path)
    assert result.returncode == 2
    assert "are for a light" in result.stderr, result.stderr
    assert all_files(tmp_path) == []


def test_unknown_material_lists_the_materials_and_writes_nothing(tmp_path):
    result = run(["--scene", OBJ, "--light-material", "lamp", "--output", "out/cornell.pvd"] + PATH + FAST,
                 tmp_path)
    assert result.returncode == 1
    assert "no material named 'lamp'" in result.stderr and "'light'" in result.stderr \
        and "'floor'" in result.stderr, result.stderr
    assert all_files(tmp_path) == []


def test_light_material_goes_without_light(tmp_path):
    result = run(["--scene", OBJ, "--light-material", "light", "--light",
                  os.path.join(DATA, "cornell_light.vtp")] + PATH + FAST, tmp_path)
    assert result.returncode == 2
    assert "--light-material" in result.stderr
    assert all_files(tmp_path) == []


def test_missing_mtl_falls_back_to_grey_with_a_warning(tmp_path):
    scene = copy_scene(tmp_path)
    os.remove(tmp_path / "CornellBox-Original.mtl")
    result = run(["--scene", scene, "--light", os.path.join(DATA, "cornell_light.vtp"),
                  "--output", "out/cornell.pvd"] + PATH + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    assert "CornellBox-Original.mtl" in result.stderr, result.stderr


def write_png(path, rgb):
    """A 2 x 2 PNG of one sRGB colour `rgb` (0-255)."""
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter
    from vtkmodules.vtkCommonCore import VTK_UNSIGNED_CHAR
    image = vtkImageData()
    image.SetDimensions(2, 2, 1)
    image.AllocateScalars(VTK_UNSIGNED_CHAR, 3)
    texels = image.GetPointData().GetScalars()
    for t in range(4):
        for c in range(3):
            texels.SetComponent(t, c, rgb[c])
    writer = vtkPNGWriter()
    writer.SetFileName(str(path))
    writer.SetInputData(image)
    writer.Write()


def test_map_kd_texture_mean_multiplies_kd_and_a_bad_texture_is_a_warning(tmp_path):
    """map_Kd: Kd times the texture's mean linear colour reaches the output; a texture that is no
    image (here a device) is a warning naming the material and the file, and Kd alone stays."""
    scene = copy_scene(tmp_path)
    (tmp_path / "textures").mkdir()
    write_png(tmp_path / "textures" / "bricks.png", (128, 64, 255))
    mtl = (tmp_path / "CornellBox-Original.mtl").read_text()
    mtl = mtl.replace("newmtl leftWall\n", "newmtl leftWall\nmap_Kd -s 2 2 1 -bm 1 textures\\bricks.png\n")
    mtl = mtl.replace("newmtl rightWall\n", "newmtl rightWall\nmap_Kd /dev/zero\n")
    (tmp_path / "CornellBox-Original.mtl").write_text(mtl)
    result = run(["--scene", scene, "--light", os.path.join(DATA, "cornell_light.vtp"),
                  "--output", "out/cornell.pvd"] + PATH + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    assert "'rightWall'" in result.stderr and "'/dev/zero'" in result.stderr, result.stderr

    def linear(value):
        value /= 255
        return value / 12.92 if value <= 0.04045 else ((value + 0.055) / 1.055) ** 2.4

    rho = vtk_to_numpy(frame(tmp_path, 0).GetCellData().GetArray("Reflectance"))
    textured = [kd * linear(v) for kd, v in zip((0.63, 0.065, 0.05), (128, 64, 255))]
    assert (abs(rho - textured).max(axis=1) < 1e-6).any(), textured
    assert not (abs(rho - (0.63, 0.065, 0.05)).max(axis=1) < 1e-6).any()
    assert (abs(rho - (0.14, 0.45, 0.091)).max(axis=1) < 1e-6).any()

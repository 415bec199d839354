"""The command line moving-light-radiosity: the series it writes reads back with VTK's readers,
and bad options, unreadable files and failed solves leave no (or no new) files behind.

ctest sets MLR_CLI (the executable) and MLR_DATA_DIR (Data/); by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps
"""
import json
import os
import re
import subprocess
import sys
import shutil
import xml.etree.ElementTree as ElementTree

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from cli_support import CLI, FAST, LIGHT, SCENE, all_files, run, write_polydata  # noqa: E402

from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
from vtkmodules.vtkCommonCore import vtkPoints, vtkDoubleArray
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkIOImage import vtkPNGReader
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader
from paraview.modules.vtkPVVTKExtensionsIOCore import vtkPVDReader

PATH = ["--from", "0.15,0.5478,0.15", "--to", "0.40,0.5478,0.40"]
ARRAYS = ("Radiosity", "DirectRadiosity", "IndirectRadiosity", "RadiosityFront",
          "RadiosityBack", "Reflectance", "PatchId")


def read_grid(path):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def field(data, name):
    return data.GetFieldData().GetArray(name).GetValue(0)


def read_scene():
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(SCENE)
    reader.Update()
    scene = vtkPolyData()
    scene.DeepCopy(reader.GetOutput())
    return scene


def test_help(tmp_path):
    result = run(["--help"], tmp_path)
    assert result.returncode == 0
    assert "--scene FILE" in result.stdout and "--png DIR" in result.stdout
    assert all_files(tmp_path) == []


def test_series_reads_back_with_frames_arrays_and_times(tmp_path):
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                 ["--frames", "4", "--output", "out/series.pvd", "--stats", "out/stats.json"] +
                 FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    assert "4 frames" in result.stdout and "predicted speed-up" in result.stdout
    assert "\r" not in result.stdout  # no progress bar when stdout is not a terminal
    assert all_files(tmp_path / "out") == [
        "series.pvd", "series_0000.vtu", "series_0001.vtu", "series_0002.vtu",
        "series_0003.vtu", "stats.json"]

    reader = vtkPVDReader()
    reader.SetFileName(str(tmp_path / "out" / "series.pvd"))
    reader.UpdateInformation()
    steps = reader.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS())
    assert steps == (0.0, 1.0, 2.0, 3.0)
    for t in steps:
        reader.UpdateTimeStep(t)
        assert reader.GetOutputDataObject(0).GetNumberOfCells() > 0

    datasets = ElementTree.parse(tmp_path / "out" / "series.pvd").findall(".//DataSet")
    previous = None
    for frame, dataset in enumerate(datasets):
        grid = read_grid(tmp_path / "out" / dataset.get("file"))
        assert grid.GetNumberOfCells() > 0
        for name in ARRAYS:
            assert grid.GetCellData().GetArray(name) is not None, name
        assert field(grid, "TimeValue") == float(dataset.get("timestep")) == frame
        assert field(grid, "FrameIndex") == frame
        radiosity = grid.GetCellData().GetArray("Radiosity").GetRange(-1)
        assert radiosity[1] > 0 and radiosity != previous
        previous = radiosity

    stats = json.loads((tmp_path / "out" / "stats.json").read_text())
    assert stats["statistics"]["Frames"] == 4
    assert stats["statistics"]["Elements"] == grid.GetNumberOfCells()
    assert [f["time"] for f in stats["frames"]] == [0, 1, 2, 3]
    assert stats["settings"]["paths"] == 20000


def test_trajectory_file_gives_positions_and_times(tmp_path):
    trajectory = vtkPolyData()
    points = vtkPoints()
    for x in (0.15, 0.25, 0.40):
        points.InsertNextPoint(x, 0.5478, x)
    trajectory.SetPoints(points)
    times = vtkDoubleArray()
    times.SetName("Time")
    for t in (0.0, 0.5, 2.0):
        times.InsertNextValue(t)
    trajectory.GetPointData().AddArray(times)
    write_polydata(trajectory, tmp_path / "path.vtp")

    result = run(["--scene", SCENE, "--light", LIGHT, "--trajectory", "path.vtp",
                  "--output", "series.pvd"] + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    datasets = ElementTree.parse(tmp_path / "series.pvd").findall(".//DataSet")
    assert [float(d.get("timestep")) for d in datasets] == [0.0, 0.5, 2.0]
    grid = read_grid(tmp_path / datasets[1].get("file"))
    assert grid.GetFieldData().GetArray("LightPosition").GetTuple(0) == pytest.approx(
        (0.25, 0.5478, 0.25))


def test_shorter_run_replaces_the_whole_series(tmp_path):
    base = ["--scene", SCENE, "--light", LIGHT, "--output", "s.pvd"] + PATH + FAST
    assert run(base + ["--frames", "4"], tmp_path).returncode == 0
    assert run(base + ["--frames", "2"], tmp_path).returncode == 0
    assert all_files(tmp_path) == ["s.pvd", "s_0000.vtu", "s_0001.vtu"]
    assert len(ElementTree.parse(tmp_path / "s.pvd").findall(".//DataSet")) == 2


@pytest.mark.parametrize("args, message", [
    (["--bogus"], "unknown option --bogus"),
    (["--paths", "many"], "--paths needs a whole number"),
    (["--survival", "0"], "--survival is 0"),
    (["--frames", "3"], "--frames needs --from and --to"),
    (["--scene", SCENE], "--scene needs --light"),
    (["--output", "series.vtu"], "ending in .pvd"),
    (["--reuse", "sometimes"], "give none, gathering, shooting or both"),
    (["--equal-shares", "--reuse", "none"], "give it with --reuse shooting or both"),
    # Numbers as given, not as std::to_string shows a double ("0.000000").
    (["--light-lumens", "0"], "--light-lumens is 0: give"),
    (["--spot", "30,-1"], "--spot is 30,-1: give"),
    (["--equal-shares", "--reuse", "gathering"], "give it with --reuse shooting or both"),
])
def test_bad_option_fails_with_a_message_and_writes_nothing(tmp_path, args, message):
    result = run(args + ["--output", "out/x.pvd"] if "--output" not in args else args, tmp_path)
    assert result.returncode == 2
    assert message in result.stderr
    assert all_files(tmp_path) == []


# The syntax CLI11 parses, each line as given: no --output is appended.
@pytest.mark.parametrize("args, message", [
    (["--paths=many"], "--paths needs a whole number, not 'many'"),
    (["--bogus=3"], "unknown option --bogus"),
    (["scene.vtp"], "unexpected argument 'scene.vtp': every option starts with --"),
    (["-x"], "unexpected argument '-x': every option starts with --"),
    (["--paths"], "--paths needs a value: --paths N"),
    (["--paths=", "5"], "--paths needs a value: --paths N"),
    (["--scene", ""], "--scene needs a value: --scene FILE"),
    (["--frames", "3", "--frames", "4"], "--frames is given twice"),
    (["--help=no"], "--help takes no value"),
    (["--seed", "-3"], "--seed is -3: give a value from 0"),  # a value, not an option
    # CLI11 alone would read these as 16, as the largest whole number and as numbers.
    (["--seed", "0x10"], "--seed needs a whole number, not '0x10'"),
    (["--paths", "99999999999999999999"],
     "--paths needs a whole number, not '99999999999999999999'"),
    (["--survival", "inf"], "--survival needs a number, not 'inf'"),
    (["--gather-ratio", "1e999"], "--gather-ratio needs a number, not '1e999'"),
    (["--from", "1,2"], "--from needs three numbers X,Y,Z, not '1,2'"),
    (["--aim", "1,2,3,"], "--aim needs three numbers X,Y,Z, not '1,2,3,'"),
    (["--light-power", "1,2"], "--light-power needs three numbers R,G,B, not '1,2'"),
    (["--light-lumens", "1000", "--light-power", "0,0,0"],
     "--light-lumens takes the light's colour from --light-power, which is 0,0,0, black"),
    # CLI11 takes the next word as the value: these solved and wrote a file named --help.
    (["--stats", "--help"], "--stats needs a value: --stats FILE.json, not the option '--help'"),
    (["--png", "--help"], "--png needs a value: --png DIR, not the option '--help'"),
    (["--output", "--help"], "--output needs a value: --output PATH.pvd, not the option"),
    (["--scene", "--help"], "--scene needs a value: --scene FILE, not the option '--help'"),
])
def test_bad_syntax_fails_with_a_message_and_writes_nothing(tmp_path, args, message):
    result = run(args, tmp_path)
    assert result.returncode == 2
    assert message in result.stderr, result.stderr
    assert all_files(tmp_path) == []


def test_every_option_of_the_help_is_known(tmp_path):
    """Every option the help lists is registered: alone, it asks for its value (the flags
    --help, --point-light, --night, --luminaire and --equal-shares take none)."""
    options = sorted(set(re.findall(r"--[a-z][a-z-]+", run(["--help"], tmp_path).stdout)) -
                     {"--help", "--point-light", "--night", "--luminaire", "--equal-shares"})
    assert len(options) == 44, options
    for option in options:
        result = run([option], tmp_path)
        assert result.returncode == 2
        assert f"{option} needs a value: {option} " in result.stderr, result.stderr
    assert all_files(tmp_path) == []


def test_equals_syntax(tmp_path):
    result = run(["--scene=" + SCENE, "--light=" + LIGHT, "--from=0.15,0.5478,0.15",
                  "--to", "0.40,0.5478,0.40", "--frames=2", "--seed=3", "--paths=20000",
                  "--patch-size=0.08", "--output=s.pvd", "--stats=s.json"], tmp_path)
    assert result.returncode == 0, result.stderr
    settings = json.loads((tmp_path / "s.json").read_text())["settings"]
    assert settings["paths"] == 20000 and settings["seed"] == 3
    assert all_files(tmp_path) == ["s.json", "s.pvd", "s_0000.vtu", "s_0001.vtu"]


@pytest.mark.parametrize("stats, words", [
    ("out/s.pvd", "is the series of --output 'out/s.pvd'"),
    ("out/s_0001.vtu", "is a frame of the series of --output 'out/s.pvd'"),
    ("out/s_0012.vtu", "is a frame of the series of --output 'out/s.pvd'"),  # no such frame yet
    ("out/../out/s_sensors.pvd", "is a file of the sensors' series of --output 'out/s.pvd'"),
    ("out/s_sensors_0000.vtp", "is a file of the sensors' series of --output 'out/s.pvd'"),
    ("pictures", "is the folder of --png 'pictures'"),
    ("pictures/s_0001.png", "is the folder of --png 'pictures' or one of its pictures"),
])
def test_stats_on_a_file_of_the_run_is_refused_and_keeps_the_earlier_series(tmp_path, stats,
                                                                            words):
    """The statistics were staged under the name of a file of the series: the commit renamed
    half of the files, then failed, leaving JSON in the .pvd (or a frame)."""
    base = ["--scene", SCENE, "--light", LIGHT, "--output", "out/s.pvd", "--frames", "2"] + \
        PATH + FAST
    assert run(base, tmp_path).returncode == 0
    before = {name: (tmp_path / name).read_bytes() for name in all_files(tmp_path)}
    pictures = ["--png", "pictures"] if stats.startswith("pictures") else []
    result = run(base + ["--light-power", "5", "--stats", stats] + pictures, tmp_path)
    assert result.returncode == 2, result.stderr
    assert f"--stats '{stats}' {words}" in result.stderr, result.stderr
    assert "give the statistics a file of their own, e.g. --stats out/s.json" in result.stderr
    assert {name: (tmp_path / name).read_bytes() for name in all_files(tmp_path)} == before


def test_unknown_scene_extension_names_every_format_read(tmp_path):
    """The scene's formats are VTK's readers' and the scene reader's (glTF too); a light file
    is read by VTK's alone."""
    (tmp_path / "lamp.ies").write_text("IESNA:LM-63-2002\n")
    result = run(["--scene", "lamp.ies", "--light", LIGHT, "--output", "out/x.pvd"] + PATH + FAST,
                 tmp_path)
    assert result.returncode == 1
    assert "the scene file 'lamp.ies' has an unknown extension: give a .vtp .vtu .vtk .obj .ply " \
        ".stl .gltf or .glb file" in result.stderr, result.stderr
    result = run(["--scene", SCENE, "--light", "lamp.ies", "--output", "out/x.pvd"] + PATH + FAST,
                 tmp_path)
    assert result.returncode == 1
    assert "the light file 'lamp.ies' has an unknown extension: give a .vtp .vtu .vtk .obj .ply " \
        "or .stl file" in result.stderr, result.stderr
    assert all_files(tmp_path) == ["lamp.ies"]


def test_unreadable_files_fail_with_a_message_and_write_nothing(tmp_path):
    (tmp_path / "inputs").mkdir()
    garbage = tmp_path / "inputs" / "garbage.vtp"
    garbage.write_text("this is not a VTK file\n")
    for scene, message in ((str(garbage), "garbage.vtp' is not a VTK XML PolyData file"),
                           ("missing.obj", "missing.obj' does not exist")):
        result = run(["--scene", scene, "--light", LIGHT, "--output", "out/x.pvd"] + PATH + FAST,
                     tmp_path)
        assert result.returncode == 1
        assert message in result.stderr
        assert all_files(tmp_path) == ["inputs/garbage.vtp"]


def test_failed_solve_keeps_the_previous_series(tmp_path):
    base = ["--light", LIGHT, "--output", "s.pvd", "--frames", "3"] + PATH + FAST
    assert run(["--scene", SCENE] + base, tmp_path).returncode == 0
    before = {name: (tmp_path / name).read_bytes() for name in all_files(tmp_path)}

    scene = read_scene()  # the same box with one reflectance out of range
    scene.GetCellData().GetArray("Reflectance").SetComponent(2, 0, 1.5)
    write_polydata(scene, tmp_path / "bad.vtp")
    result = run(["--scene", "bad.vtp"] + base, tmp_path)
    assert result.returncode == 1
    assert "Scene cell 2 has Reflectance (1.5" in result.stderr
    assert "returned failure" not in result.stderr  # no pipeline dump
    after = {name: (tmp_path / name).read_bytes() for name in all_files(tmp_path)
             if name != "bad.vtp"}
    assert after == before


def test_remeshing_warnings_show_before_the_solve(tmp_path):
    """A ball of 6,960 triangles at a patch size of 10 cm keeps its triangles, far more patches
    than the patch size aims at: the warning comes once, as soon as the scene is built, before
    the solve's first line, and also when the solve is then refused for its memory."""
    ball = vtkSphereSource()
    ball.SetCenter(0.28, 0.2, 0.28)
    ball.SetRadius(0.1)
    ball.SetThetaResolution(60)
    ball.SetPhiResolution(60)
    ball.Update()
    write_polydata(ball.GetOutput(), tmp_path / "ball.vtp")
    common = ["--scene", "ball.vtp", "--light", LIGHT, "--from", "0.25,0.5478,0.25", "--to",
              "0.3,0.5478,0.3", "--frames", "6", "--paths", "20000", "--patch-size", "0.1",
              "--threads", "2"]
    # Both streams in one pipe, in the order they were written.
    result = subprocess.run([CLI] + common + ["--frames-per-chunk", "3", "--output", "s.pvd"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, timeout=300)
    assert result.returncode == 0, result.stdout
    lines = result.stdout.splitlines()
    warnings = [i for i, line in enumerate(lines) if "the scene keeps 6960 patches" in line]
    assert len(warnings) == 1, result.stdout
    solve = next(i for i, line in enumerate(lines) if line.startswith("chunk 1 of 2"))
    assert warnings[0] < solve, result.stdout

    # Remeshing fits in 16 MiB (about 10), the solve does not (about 43): refused after the
    # scene is built, with the warning that says why it has so many patches.
    refused = run(common + ["--memory-limit", "16", "--output", "r.pvd"], tmp_path)
    assert refused.returncode == 1
    assert "the solve needs an estimated" in refused.stderr
    assert refused.stderr.count("the scene keeps 6960 patches") == 1, refused.stderr


@pytest.mark.skipif(shutil.which("Xvfb") is None, reason="needs Xvfb")
def test_pictures_show_the_light_moving(tmp_path):
    env = dict(os.environ)
    env.pop("DISPLAY", None)  # exercises the private Xvfb the program starts
    result = run(["--scene", SCENE, "--light", LIGHT, "--output", "s.pvd", "--png", "pictures",
                  "--frames", "3"] + PATH + FAST, tmp_path, env=env)
    assert result.returncode == 0, result.stderr
    pictures = [tmp_path / "pictures" / f"s_000{i}.png" for i in range(3)]
    assert all_files(tmp_path / "pictures") == [p.name for p in pictures]

    def pixels(path):
        reader = vtkPNGReader()
        reader.SetFileName(str(path))
        reader.Update()
        scalars = reader.GetOutput().GetPointData().GetScalars()
        return [scalars.GetComponent(i, 1) for i in range(0, scalars.GetNumberOfTuples(), 7)]

    first, last = pixels(pictures[0]), pixels(pictures[2])
    mean = sum(first) / len(first)
    assert 20 < mean < 235  # neither blank nor blown out
    assert max(first) - min(first) > 100
    assert sum(abs(a - b) for a, b in zip(first, last)) / len(first) > 2


def test_default_run_writes_the_cornell_box_animation(tmp_path):
    env = dict(os.environ)
    if shutil.which("Xvfb") is None and not env.get("DISPLAY"):
        pytest.skip("the default run renders pictures: needs Xvfb or a display")
    result = run([], tmp_path, env=env)
    assert result.returncode == 0, result.stderr
    assert "30 frames" in result.stdout
    files = all_files(tmp_path / "output")
    assert "cornell.pvd" in files
    assert len([f for f in files if f.endswith(".vtu")]) == 30
    assert len([f for f in files if f.startswith("png/") and f.endswith(".png")]) == 30
    assert not [f for f in files if f.endswith(".partial")]

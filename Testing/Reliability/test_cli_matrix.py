"""The bad-input matrix for the command line moving-light-radiosity: one row per kind
of bad input, file or option. Every row asserts the exit status, the message and that no
output file (nor a partial one) is left behind; rows that succeed assert what was written.
The filter's rows are in TestFilterMatrix.cxx. No row may leave a process behind: this process
adopts the orphans of the command line (PR_SET_CHILD_SUBREAPER), so that a reading process that
outlived the command line would show up as its child.

ctest sets MLR_CLI and MLR_DATA_DIR; by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Reliability
"""
import ctypes
import os
import sys
import signal
import subprocess
import time
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass, field
from typing import Callable, Optional

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from cli_support import CLI, DATA, FAST, LIGHT, SCENE, all_files, run, write_polydata  # noqa: E402

from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader

import numpy

HANG_REGRESSION = os.path.join(os.path.dirname(__file__), os.pardir, "Fuzz", "regressions",
                               "readers", "vtk_legacy_reader_loops_forever")

PATH = ["--from", "0.15,0.5478,0.15", "--to", "0.40,0.5478,0.40", "--frames", "2"]
OUTPUT = ["--output", "out/series.pvd"]


# --- Inputs ------------------------------------------------------------------------------
def read_box():
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(SCENE)
    reader.Update()
    box = vtkPolyData()
    box.DeepCopy(reader.GetOutput())
    return box


def box_with_reflectance(rgb):
    def make(directory):
        box = read_box()
        box.GetCellData().GetArray("Reflectance").SetTuple3(3, *rgb)
        write_polydata(box, directory / "scene.vtp", compressed=False)
    return make


def box_with_point(point):
    def make(directory):
        box = read_box()
        box.GetPoints().SetPoint(2, *point)
        write_polydata(box, directory / "scene.vtp", compressed=False)
    return make


def text(name, content):
    def make(directory):
        (directory / name).write_bytes(content if isinstance(content, bytes) else
                                       content.encode())
    return make


def truncated(name, source_writer, keep=0.5):
    def make(directory):
        source_writer(directory)
        path = directory / name
        data = path.read_bytes()
        path.write_bytes(data[:int(len(data) * keep)])
    return make


def binary_stl(directory):
    """The Cornell box as a binary STL file (84-byte header, 50 bytes per triangle)."""
    from vtkmodules.vtkFiltersCore import vtkTriangleFilter
    from vtkmodules.vtkIOGeometry import vtkSTLWriter
    triangles = vtkTriangleFilter()
    triangles.SetInputData(read_box())
    writer = vtkSTLWriter()
    writer.SetInputConnection(triangles.GetOutputPort())
    writer.SetFileTypeToBinary()
    writer.SetFileName(str(directory / "scene.stl"))
    assert writer.Write()


def binary_ply(directory):
    from vtkmodules.vtkIOPLY import vtkPLYWriter
    writer = vtkPLYWriter()
    writer.SetInputData(read_box())
    writer.SetFileTypeToBinary()
    writer.SetFileName(str(directory / "scene.ply"))
    assert writer.Write()


def scene_vtp(directory):
    write_polydata(read_box(), directory / "scene.vtp", compressed=False)


def copy_as(name, source):
    def make(directory):
        (directory / name).write_bytes((directory / source).read_bytes())
    return make


def ten_million_duplicated_points(directory):
    """10^7 points at three positions: 3.3 million copies of one triangle, zlib-compressed."""
    n = 10_000_000
    corners = numpy.array([[0.1, 0.01, 0.1], [0.5, 0.01, 0.1], [0.1, 0.01, 0.5]],
                          dtype=numpy.float32)
    points = vtkPoints()
    points.SetData(numpy_to_vtk(numpy.tile(corners, (n // 3 + 1, 1))[:n], deep=True))
    triangles = n // 3
    offsets = numpy.arange(0, 3 * triangles + 1, 3, dtype=numpy.int64)
    connectivity = numpy.arange(3 * triangles, dtype=numpy.int64)
    cells = vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True),
                  numpy_to_vtkIdTypeArray(connectivity, deep=True))
    scene = vtkPolyData()
    scene.SetPoints(points)
    scene.SetPolys(cells)
    write_polydata(scene, directory / "scene.vtp", compressed=True)


def trajectory(points):
    def make(directory):
        data = vtkPolyData()
        vtk_points = vtkPoints()
        for p in points:
            vtk_points.InsertNextPoint(*p)
        data.SetPoints(vtk_points)
        write_polydata(data, directory / "path.vtp", compressed=False)
    return make


def fuzz_input(name, path):
    """A fuzz regression of mlr-fuzz-readers as a file: its first byte only chose the extension."""
    def make(directory):
        with open(path, "rb") as regression:
            (directory / name).write_bytes(regression.read()[1:])
    return make


def each(*makers):
    def make(directory):
        for m in makers:
            m(directory)
    return make


OBJ_LIGHT_UP = "v 0.2 0.5 0.2\nv 0.2 0.5 0.35\nv 0.35 0.5 0.35\nv 0.35 0.5 0.2\nf 1 2 3 4\n"
OBJ_LIGHT_DOWN = "v 0.2 0.5 0.2\nv 0.35 0.5 0.2\nv 0.35 0.5 0.35\nv 0.2 0.5 0.35\nf 1 2 3 4\n"
OBJ_FLOOR = "v 0 0 0\nv 0 0 0.6\nv 0.6 0 0.6\nv 0.6 0 0\nf 1 2 3 4\n"


# --- The matrix --------------------------------------------------------------------------
@dataclass
class Row:
    name: str
    make: Callable  # writes the inputs into the directory
    args: list      # beyond the output
    status: int
    message: str
    stream: str = "stderr"
    seconds: float = 120
    outputs: list = field(default_factory=list)  # files expected on success, under out/
    check: Optional[Callable] = None


def scene_args(scene, light=LIGHT, path=PATH, paths=20000):
    return ["--scene", scene, "--light", light] + path + ["--paths", str(paths),
                                                          "--patch-size", "0.08"]


ROWS = [
    Row("empty_vtp", text("scene.vtp", b""), scene_args("scene.vtp"), 1,
        "the scene file 'scene.vtp' is empty"),
    Row("empty_obj", text("scene.obj", b""), scene_args("scene.obj"), 1,
        "the scene file 'scene.obj' is empty"),
    Row("empty_stl", text("scene.stl", b""), scene_args("scene.stl"), 1, "is empty"),
    Row("empty_ply", text("scene.ply", b""), scene_args("scene.ply"), 1, "is empty"),
    Row("truncated_vtp", truncated("scene.vtp", scene_vtp), scene_args("scene.vtp"), 1,
        "scene.vtp"),
    Row("truncated_binary_stl", truncated("scene.stl", binary_stl), scene_args("scene.stl"), 1,
        "is a binary STL file whose header counts"),
    # Scene .ply and .obj files are read with their materials by vtkRadiositySceneReader.
    Row("truncated_binary_ply", truncated("scene.ply", binary_ply), scene_args("scene.ply"), 1,
        "it is truncated or its header counts more elements than it holds"),
    Row("vtp_named_ply", copy_as("scene.ply", SCENE), scene_args("scene.ply"), 1,
        "is not a PLY file: it does not start with 'ply'"),
    Row("ply_named_vtp", each(binary_ply, copy_as("scene.vtp", "scene.ply")),
        scene_args("scene.vtp"), 1, "is not a VTK XML PolyData file"),
    Row("vtp_named_stl", copy_as("scene.stl", SCENE), scene_args("scene.stl"), 1,
        "is a binary STL file whose header counts"),
    Row("stl_named_obj", each(binary_stl, copy_as("scene.obj", "scene.stl")),
        scene_args("scene.obj"), 1, "scene.obj"),
    # VTK 9.2's legacy reader loops for ever on it: the CPU-time limit of the reading process
    # (5 s for a small file; 20 s of wall-clock time) refuses it.
    Row("legacy_vtk_reader_loops_forever", fuzz_input("scene.vtk", HANG_REGRESSION),
        scene_args("scene.vtk"), 1,
        "VTK's .vtk reader did not finish reading the scene file 'scene.vtk' within", seconds=40),
    Row("only_lines_and_points", text("scene.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\np 1\n"),
        scene_args("scene.obj"), 1, "has no faces ('f' lines): there is no surface to light"),
    Row("one_triangle", text("scene.obj", "v 0 0 0\nv 0 0 0.6\nv 0.6 0 0\nf 1 2 3\n"),
        scene_args("scene.obj"), 0, "wrote out/series.pvd and 2 frames", stream="stdout",
        outputs=["series.pvd", "series_0000.vtu", "series_0001.vtu"]),
    Row("all_degenerate_triangles",
        text("scene.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\nf 3 3 3\n"),
        scene_args("scene.obj"), 1, "the scene has no polygon with an area"),
    Row("nan_coordinates", box_with_point((0.2, float("nan"), 0.1)), scene_args("scene.vtp"), 1,
        "1 point with NaN or infinite coordinates"),
    Row("infinite_coordinates", box_with_point((float("inf"), 0, 0)), scene_args("scene.vtp"),
        1, "1 point with NaN or infinite coordinates"),
    Row("coordinates_beyond_ray_tracing", box_with_point((0, 1e20, 0)),
        scene_args("scene.vtp"), 1, "coordinates must stay within +-1e+15"),
    Row("ten_million_duplicated_points", ten_million_duplicated_points,
        scene_args("scene.vtp"), 0, "ignored 3333332 duplicate polygons", seconds=60,
        outputs=["series.pvd", "series_0000.vtu", "series_0001.vtu"]),
    Row("reflectance_of_one", box_with_reflectance((1, 1, 1)), scene_args("scene.vtp"), 1,
        "Scene cell 3 has Reflectance (1, 1, 1): every value must be >= 0 and < 1"),
    Row("negative_reflectance", box_with_reflectance((0.5, -0.2, 0.5)),
        scene_args("scene.vtp"), 1, "Scene cell 3 has Reflectance (0.5, -0.2, 0.5)"),
    Row("nan_reflectance", box_with_reflectance((float("nan"), 0.5, 0.5)),
        scene_args("scene.vtp"), 1, "Scene cell 3 has Reflectance (nan, 0.5, 0.5)"),
    Row("light_with_zero_area",
        text("light.obj", "v 0.2 0.5 0.2\nv 0.3 0.5 0.2\nv 0.4 0.5 0.2\nf 1 2 3\n"),
        scene_args(SCENE, "light.obj"), 1, "is degenerate (zero area)"),
    Row("light_facing_away",
        each(text("floor.obj", OBJ_FLOOR), text("light.obj", OBJ_LIGHT_UP)),
        scene_args("floor.obj", "light.obj"), 0, "no light reached the scene",
        outputs=["series.pvd", "series_0000.vtu", "series_0001.vtu"],
        check=lambda directory: all_radiosity_zero(directory / "out")),
    Row("trajectory_of_no_point", trajectory([]),
        ["--scene", SCENE, "--light", LIGHT, "--trajectory", "path.vtp"] + FAST, 1,
        "the trajectory file 'path.vtp' has no points"),
    Row("trajectory_of_one_point", trajectory([(0.3, 0.5478, 0.3)]),
        ["--scene", SCENE, "--light", LIGHT, "--trajectory", "path.vtp"] + FAST, 0,
        "wrote out/series.pvd and 1 frame", stream="stdout",
        outputs=["series.pvd", "series_0000.vtu"]),
    # In one chunk: left to the memory limit, chunks would solve it (slowly).
    Row("ten_thousand_frames_in_one_chunk_on_a_large_scene", lambda directory: None,
        ["--scene", SCENE, "--light", LIGHT, "--from", "0.15,0.5478,0.15", "--to",
         "0.40,0.5478,0.40", "--frames", "10000", "--patch-size", "0.004",
         "--frames-per-chunk", "10000"], 1,
        "the solve needs an estimated", seconds=30,
        check=lambda directory: None),
    Row("paths_zero", lambda directory: None, ["--paths", "0"], 2,
        "--paths is 0: give a value from 1 to 100000000000"),
    Row("paths_two_to_the_62", lambda directory: None, ["--paths", str(2 ** 62)], 2,
        "--paths is 4611686018427387904: give a value from 1 to 100000000000"),
    Row("memory_limit_zero", lambda directory: None, ["--memory-limit", "0"], 2,
        "--memory-limit is 0"),
    Row("memory_limit_refuses_the_solve", lambda directory: None,
        scene_args(SCENE) + ["--memory-limit", "1"], 1, "over the memory limit of 0.000977 GiB"),
    # Weather files (Core's reader): a pipe is not read (it could block forever), a file cut
    # short is named with its last hour, a file of another format is named at its first line.
    Row("weather_file_is_a_pipe", lambda directory: os.mkfifo(directory / "w.epw"),
        ["--scene", SCENE, "--weather", "w.epw"] + FAST, 1,
        "the weather file w.epw is not a regular file", seconds=20),
    Row("weather_file_cut_short", text("w.epw", "".join(
        open(os.path.join(DATA, "paris_synthetic.epw")).readlines()[:5008])),
        ["--scene", SCENE, "--weather", "w.epw"] + FAST, 1,
        "has 5000 hourly lines (lines 9 to 5008), the last July 28 hour 8", seconds=20),
    Row("weather_file_is_a_scene", copy_as("w.epw", SCENE), ["--scene", SCENE, "--weather",
                                                             "w.epw"] + FAST, 1,
        "the weather file w.epw, line 1: starts with '<?xml version=\"1.0\"?>', not LOCATION",
        seconds=20),
]


# --- Processes ---------------------------------------------------------------------------
PR_SET_CHILD_SUBREAPER = 36


@pytest.fixture(autouse=True, scope="module")
def adopt_orphans():
    libc = ctypes.CDLL(None, use_errno=True)
    assert libc.prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0, os.strerror(ctypes.get_errno())
    yield
    libc.prctl(PR_SET_CHILD_SUBREAPER, 0, 0, 0, 0)


def processes_left(seconds=0.0):
    """The command lines of this process's children: after a run, processes the command line
    left behind. Waits up to `seconds` for them to end (a process killed by its parent's death
    ends a moment after it); the dead are reaped."""
    deadline = time.monotonic() + seconds
    while True:
        try:
            while os.waitpid(-1, os.WNOHANG)[0] != 0:
                pass
        except ChildProcessError:
            return []
        if time.monotonic() >= deadline:
            break
        time.sleep(0.05)
    left = []
    for pid in children_of(os.getpid()):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as cmdline:
                left.append(cmdline.read().replace(b"\0", b" ").decode(errors="replace"))
        except OSError:
            continue  # ended meanwhile
    return left


def children_of(parent):
    children = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/stat") as stat:
                # pid (comm) state ppid ...: comm may hold spaces and parentheses
                if int(stat.read().rsplit(")", 1)[1].split()[1]) == parent:
                    children.append(int(pid))
        except (OSError, IndexError, ValueError):
            continue  # ended meanwhile
    return children


def all_radiosity_zero(directory):
    for name in os.listdir(directory):
        if name.endswith(".vtu"):
            reader = vtkXMLUnstructuredGridReader()
            reader.SetFileName(str(directory / name))
            reader.Update()
            radiosity = reader.GetOutput().GetCellData().GetArray("Radiosity")
            assert radiosity is not None
            for c in range(3):
                assert radiosity.GetRange(c) == (0.0, 0.0), name


@pytest.mark.parametrize("row", ROWS, ids=[r.name for r in ROWS])
def test_row(tmp_path, row):
    row.make(tmp_path)
    inputs = all_files(tmp_path)
    start = time.monotonic()
    result = run(row.args + OUTPUT, tmp_path, timeout=row.seconds * 3)
    seconds = time.monotonic() - start
    assert result.returncode == row.status, result.stderr
    output = result.stdout if row.stream == "stdout" else result.stderr
    assert row.message in output, result.stderr
    assert seconds < row.seconds
    assert "returned failure" not in result.stderr  # no pipeline dumps
    assert processes_left() == []
    written = [f for f in all_files(tmp_path) if f not in inputs]
    assert not [f for f in written if ".partial" in f or ".mlr-write-test" in f], written
    if row.status == 0:
        assert written == ["out/" + f for f in row.outputs]
    else:
        assert written == [], "a failed run left files behind"
        assert not (tmp_path / "out").exists(), "a failed run left its directory behind"
    if row.check:
        row.check(tmp_path)


# --- Output locations --------------------------------------------------------------------
def unwritable_directory(tmp_path):
    """An existing directory no file can be created in (root writes through permissions:
    /sys then)."""
    if os.geteuid() == 0:
        return "/sys"
    directory = tmp_path / "read-only"
    directory.mkdir()
    directory.chmod(0o555)
    return str(directory)


def test_unwritable_output_folder_fails_before_solving(tmp_path):
    directory = unwritable_directory(tmp_path)
    before = sorted(os.listdir(directory))
    start = time.monotonic()
    result = run(scene_args(SCENE, paths=5000000) + [
        "--output", os.path.join(directory, "series.pvd")], tmp_path)
    assert result.returncode == 1
    assert f"cannot write in the directory '{directory}'" in result.stderr
    assert time.monotonic() - start < 20, "the solve ran before the output was checked"
    assert sorted(os.listdir(directory)) == before
    assert all_files(tmp_path) == [] or directory.startswith(str(tmp_path))


def test_a_system_directory_is_not_said_to_be_missing(tmp_path):
    # /proc exists and refuses new files with "No such file or directory", which the message
    # passed on as if the directory were missing.
    result = run(["--paths", "20000", "--output", "/proc/series.pvd"], tmp_path)
    assert result.returncode == 1
    assert ("cannot write in the directory '/proc': it accepts no new files (a system "
            "directory?): give a directory of your own") in result.stderr, result.stderr
    assert all_files(tmp_path) == []


def test_output_folder_that_cannot_be_created(tmp_path):
    (tmp_path / "file").write_text("in the way\n")
    result = run(scene_args(SCENE) + ["--output", "file/sub/series.pvd"], tmp_path)
    assert result.returncode == 1
    assert "cannot create the directory 'file/sub'" in result.stderr
    assert all_files(tmp_path) == ["file"]


def test_output_path_that_is_a_folder(tmp_path):
    (tmp_path / "series.pvd").mkdir()
    (tmp_path / "series.pvd" / "keep.txt").write_text("untouched\n")
    result = run(scene_args(SCENE) + ["--output", "series.pvd"], tmp_path)
    assert result.returncode == 1
    assert "the output 'series.pvd' is a directory" in result.stderr
    assert all_files(tmp_path) == ["series.pvd/keep.txt"]


def test_statistics_path_that_is_a_folder(tmp_path):
    (tmp_path / "stats.json").mkdir()
    result = run(scene_args(SCENE) + ["--output", "s.pvd", "--stats", "stats.json"], tmp_path)
    assert result.returncode == 1
    assert "the statistics file 'stats.json' is a directory" in result.stderr
    assert all_files(tmp_path) == []


# --- Interrupts --------------------------------------------------------------------------
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_interrupt_mid_solve_writes_nothing(tmp_path, sig):
    process = subprocess.Popen(
        [CLI] + scene_args(SCENE, paths=50000000) + ["--output", "out/series.pvd"],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(2.0)  # reading, remeshing and into the solve
    assert process.poll() is None, process.communicate()
    sent = time.monotonic()
    process.send_signal(sig)
    stdout, stderr = process.communicate(timeout=30)
    # Well under a second on a quiet machine; the bound only catches a process that ignores
    # the signal, whatever the machine's load.
    assert time.monotonic() - sent < 10.0, "took too long to stop"
    assert process.returncode == 1, stderr
    assert "interrupted: nothing was written" in stderr
    assert all_files(tmp_path) == []


@pytest.mark.parametrize("sig,group", [(signal.SIGINT, False), (signal.SIGINT, True),
                                       (signal.SIGTERM, False), (signal.SIGKILL, False)],
                         ids=["SIGINT", "Ctrl-C", "SIGTERM", "SIGKILL"])
def test_ending_the_program_while_it_reads_leaves_no_process(tmp_path, sig, group):
    """Ended while its reading process loops in VTK's legacy reader: an interrupt (to the
    program, or to its whole process group as Ctrl-C sends it) stops the reading at once;
    SIGKILL cannot be caught, and the reading process dies with the program."""
    fuzz_input("scene.vtk", HANG_REGRESSION)(tmp_path)
    process = subprocess.Popen(
        [CLI] + scene_args("scene.vtk") + ["--output", "out/series.pvd"],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True)
    for _ in range(200):  # up to 10 s for the reading process to start
        if children_of(process.pid):
            break
        time.sleep(0.05)
    assert children_of(process.pid), "no reading process"
    if group:
        os.killpg(process.pid, sig)
    else:
        process.send_signal(sig)
    process.wait(timeout=30)
    # The reading process has used well under its 5 s of CPU time: if it ends within 2 s, its
    # parent's death ended it, not its own limit.
    left = processes_left(seconds=2)
    for pid in children_of(os.getpid()):
        os.kill(pid, signal.SIGKILL)
    assert left == []
    stdout, stderr = process.communicate(timeout=30)
    if sig == signal.SIGKILL:
        assert process.returncode == -signal.SIGKILL
    else:
        assert process.returncode == 1, stderr
        assert "interrupted while reading the scene file 'scene.vtk': nothing was written" in stderr
    assert all_files(tmp_path) == ["scene.vtk"]


def test_failed_run_keeps_the_previous_series(tmp_path):
    base = scene_args(SCENE) + ["--output", "s.pvd"]
    assert run(base, tmp_path).returncode == 0
    before = {name: (tmp_path / name).read_bytes() for name in all_files(tmp_path)}
    result = run(base + ["--memory-limit", "1"], tmp_path)
    assert result.returncode == 1
    assert {name: (tmp_path / name).read_bytes() for name in all_files(tmp_path)} == before
    assert len(ElementTree.parse(tmp_path / "s.pvd").findall(".//DataSet")) == 2

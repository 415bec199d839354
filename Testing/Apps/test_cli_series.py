"""How the command line writes its series and pictures: LZ4-compressed frames written on
background threads read back whole and consistent, --stats times the stages, and pictures
without DISPLAY come from a private Xvfb that does not outlive the run.

ctest sets MLR_CLI (the executable) and MLR_DATA_DIR (Data/); by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps/test_cli_series.py
"""
import json
import os
import re
import shutil
import signal
import stat
import subprocess
import sys
import time
import xml.etree.ElementTree as ElementTree

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from cli_support import CLI, FAST, LIGHT, SCENE, all_files, run  # noqa: E402

from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader  # noqa: E402
import numpy  # noqa: E402

PATH = ["--from", "0.15,0.5478,0.15", "--to", "0.40,0.5478,0.40"]
FRAMES = 6
STAGES = ("secondsReading", "secondsRemeshing", "secondsSolving", "secondsWriting",
          "secondsRendering", "secondsTotal")


def read_grid(path):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


@pytest.fixture(scope="module")
def series(tmp_path_factory):
    directory = tmp_path_factory.mktemp("series")
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                 ["--frames", str(FRAMES), "--output", "out/s.pvd", "--stats", "out/s.json"] +
                 FAST, directory)
    assert result.returncode == 0, result.stderr
    return directory / "out"


def test_frames_are_lz4_compressed_and_complete(series):
    assert all_files(series) == ["s.json", "s.pvd"] + [f"s_{i:04d}.vtu" for i in range(FRAMES)]
    for i in range(FRAMES):
        header = (series / f"s_{i:04d}.vtu").read_bytes()[:200].decode("latin-1")
        assert 'compressor="vtkLZ4DataCompressor"' in header


def test_frames_read_back_with_their_times_and_one_mesh(series):
    datasets = ElementTree.parse(series / "s.pvd").findall(".//DataSet")
    stats = json.loads((series / "s.json").read_text())
    assert len(datasets) == FRAMES
    first = None
    for frame, dataset in enumerate(datasets):
        grid = read_grid(series / dataset.get("file"))
        fields = grid.GetFieldData()
        # Each file holds its own frame, whichever thread wrote it.
        assert fields.GetArray("FrameIndex").GetValue(0) == frame
        assert fields.GetArray("TimeValue").GetValue(0) == float(dataset.get("timestep"))
        assert fields.GetArray("LightPosition").GetTuple3(0) == pytest.approx(
            stats["frames"][frame]["lightPosition"], abs=0)
        points = vtk_to_numpy(grid.GetPoints().GetData())
        cells = vtk_to_numpy(grid.GetCells().GetConnectivityArray())
        types = vtk_to_numpy(grid.GetCellTypesArray())
        assert set(types.tolist()) == {5}  # VTK_TRIANGLE
        if first is None:
            first = (points, cells)
        else:
            assert numpy.array_equal(points, first[0]) and numpy.array_equal(cells, first[1])
        cell_data = grid.GetCellData()
        total = vtk_to_numpy(cell_data.GetArray("Radiosity")).astype(numpy.float64)
        parts = sum(vtk_to_numpy(cell_data.GetArray(name)).astype(numpy.float64)
                    for name in ("DirectRadiosity", "IndirectRadiosity", "EmittedRadiosity"))
        # Float32 arrays: the sum agrees within a few units in the last place.
        assert numpy.allclose(total, parts, rtol=1e-5, atol=1e-6 * total.max())
        assert cell_data.GetArray("Radiosity").GetDataType() == 10  # VTK_FLOAT, as before
        # The filter's point data too, what smooth shading and the pictures show.
        for name in ("Radiosity", "Color", "ScenePointId"):
            array = grid.GetPointData().GetArray(name)
            assert array is not None and array.GetNumberOfTuples() == len(points), name


def test_header_ranges_are_those_of_the_data(series):
    """The writer puts each array's range in the file (RangeMin/RangeMax, the norm's range for
    several components); the command line computes those ranges itself, so they are checked
    against VTK's on the arrays read back."""
    text = (series / "s_0002.vtu").read_bytes().split(b"<AppendedData")[0].decode()
    grid = read_grid(series / "s_0002.vtu")
    checked = 0
    # Point and cell data both have a Radiosity and a Color: each tag is read in its section.
    sections = {"PointData": grid.GetPointData(), "CellData": grid.GetCellData(),
                "FieldData": grid.GetFieldData()}
    section = None
    for match in re.finditer(r'<(PointData|CellData|FieldData|Points|Cells)\b|'
                             r'<DataArray [^>]*Name="([^"]+)"[^>]*>', text):
        if match.group(1):
            section = match.group(1)
            continue
        tag, name = match.group(0), match.group(2)
        low = re.search(r'RangeMin="([^"]*)"', tag)
        high = re.search(r'RangeMax="([^"]*)"', tag)
        components = int(re.search(r'NumberOfComponents="(\d+)"', tag).group(1)) \
            if "NumberOfComponents" in tag else 1
        array = grid.GetPoints().GetData() if section == "Points" else (
            sections[section].GetArray(name) if section in sections else None)
        if array is None or not low or not low.group(1):
            continue
        expected = array.GetRange(-1 if components > 1 else 0)
        assert (float(low.group(1)), float(high.group(1))) == pytest.approx(expected, rel=1e-9), \
            (section, name)
        checked += 1
    assert checked >= 14  # with the point data's Radiosity, Color and ScenePointId


def test_printed_time_is_the_whole_run_with_its_stages_as_in_stats(tmp_path):
    """The summary's time was the solve's alone: a long series printed a third of the wall
    time. The run's time, from its start to its statistics, is printed with its stages, the
    same figures as --stats (rounded as printed)."""
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                 ["--frames", str(FRAMES), "--output", "out/s.pvd", "--stats", "out/s.json"] +
                 FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    timing = json.loads((tmp_path / "out" / "s.json").read_text())["timing"]
    line = re.search(r"^(\S+) s in all: reading (\S+) s, remeshing (\S+) s, solving (\S+) s, "
                     r"writing (\S+) s$", result.stdout, re.MULTILINE)
    assert line, result.stdout
    printed = [float(value) for value in line.groups()]
    for value, key in zip(printed, ("secondsTotal", "secondsReading", "secondsRemeshing",
                                    "secondsSolving", "secondsWriting")):
        assert value == pytest.approx(timing[key], abs=0.006), key
    assert printed[4] > 0
    assert sum(printed[1:]) <= printed[0] + 0.02
    # The solver's own time is labelled as the solve's.
    assert re.search(r"gathering\), solve \S+ s \(remeshing", result.stdout), result.stdout


def test_stats_time_the_stages(series):
    stats = json.loads((series / "s.json").read_text())
    timing = stats["timing"]
    assert list(timing) == list(STAGES)
    assert all(timing[key] >= 0 for key in STAGES)
    assert timing["secondsSolving"] > 0 and timing["secondsWriting"] > 0
    assert timing["secondsRendering"] == 0  # no --png
    # Memory: the process's peak holds at least the solve's estimate of its results (the
    # estimate covers every frame's radiosity; the peak is measured, so only its floor is
    # checked), and the estimate per element-frame is stated.
    statistics = stats["statistics"]
    peak = stats["memory"]["peakResidentBytes"]
    results = FRAMES * statistics["Elements"] * 2 * 2 * 12  # direct + indirect, 2 sides, RGB floats
    assert statistics["MemoryEstimateBytes"] > results
    assert peak > results
    assert statistics["MemoryEstimateBytesPerElementFrame"] == pytest.approx(
        statistics["MemoryEstimateBytes"] / (FRAMES * statistics["Elements"]))
    # What the memory check held against the limit adds to the solve's peak the finished
    # frames, the outputs and the scene.
    assert statistics["MemoryCheckedBytes"] > statistics["MemoryEstimateBytes"]
    assert statistics["AccumulatorCopyPerWorker"] in (0, 1)
    assert 0 <= statistics["ShadowRaysBlocked"] <= statistics["ShadowRays"]
    # Disjoint stretches of the run, all within its total.
    assert sum(timing[key] for key in STAGES[:4]) <= timing["secondsTotal"]
    # The keys that were there before stay.
    assert {"scene", "light", "trajectory", "output", "settings", "statistics",
            "frames"} <= set(stats)
    assert stats["statistics"]["Frames"] == FRAMES


def fake_xvfb(directory, server=None):
    """An Xvfb on PATH that notes its process id and then becomes `server` (the real Xvfb by
    default) with the same process id."""
    server = server or f'"{shutil.which("Xvfb")}" "$@"'
    bin_dir = directory / "bin"
    bin_dir.mkdir()
    script = bin_dir / "Xvfb"
    script.write_text(f'#!/bin/sh\necho $$ >> "{directory}/xvfb.pids"\nexec {server}\n')
    script.chmod(script.stat().st_mode | stat.S_IEXEC)
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    env["PATH"] = f"{bin_dir}:{env.get('PATH', '/usr/bin:/bin')}"
    return env, directory / "xvfb.pids"


def started_pids(pids):
    """The process ids the fake Xvfb noted, whole lines only (it may be writing one)."""
    if not pids.exists():
        return []
    text = pids.read_text()
    return [int(line) for line in text[:text.rfind("\n") + 1].split()]


def alive(pid):
    """Running: a process that has exited but is not reaped yet (a zombie) is not."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            state = f.read().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return False
    return state not in ("Z", "X")


@pytest.mark.skipif(shutil.which("Xvfb") is None, reason="needs Xvfb")
def test_pictures_without_display_use_a_private_xvfb_that_stops(tmp_path):
    env, pids = fake_xvfb(tmp_path)
    result = run(["--scene", SCENE, "--light", LIGHT, "--output", "s.pvd", "--png", "pictures",
                  "--frames", "2", "--stats", "s.json"] + PATH + FAST, tmp_path, env=env)
    assert result.returncode == 0, result.stderr
    assert all_files(tmp_path / "pictures") == ["s_0000.png", "s_0001.png"]
    started = started_pids(pids)
    assert len(started) >= 1
    assert not any(alive(pid) for pid in started)  # stopped and reaped before the exit
    assert json.loads((tmp_path / "s.json").read_text())["timing"]["secondsRendering"] > 0


def test_killed_run_takes_its_xvfb_along(tmp_path):
    """The run is killed (SIGKILL: no clean-up code runs) while it waits for its X server,
    here one that never becomes ready: the server must not stay behind."""
    env, pids = fake_xvfb(tmp_path, server="sleep 600")
    process = subprocess.Popen(
        [CLI, "--scene", SCENE, "--light", LIGHT, "--output", "s.pvd", "--png", "pictures",
         "--frames", "2"] + PATH + FAST, cwd=tmp_path, env=env,
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 240
        while (not started_pids(pids) and process.poll() is None
               and time.monotonic() < deadline):
            time.sleep(0.05)
        assert started_pids(pids), "the run never started Xvfb"
        process.send_signal(signal.SIGKILL)
        process.wait(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    started = started_pids(pids)
    deadline = time.monotonic() + 30
    while any(alive(pid) for pid in started) and time.monotonic() < deadline:
        time.sleep(0.1)
    leftover = [pid for pid in started if alive(pid)]
    for pid in leftover:
        os.kill(pid, signal.SIGKILL)
    assert not leftover, "Xvfb outlived the killed run"


def test_pictures_without_display_or_xvfb_fail_before_the_solve(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    env["PATH"] = str(empty)
    result = run(["--scene", SCENE, "--light", LIGHT, "--output", "out/s.pvd", "--png", "png",
                  "--frames", "2"] + PATH + FAST, tmp_path, env=env)
    assert result.returncode == 1
    assert "--png needs an X display: set DISPLAY, or install Xvfb" in result.stderr
    assert all_files(tmp_path) == []


def test_frame_that_cannot_be_written_fails_the_run_and_leaves_nothing(tmp_path):
    """A frame's file fails on a writing thread, after earlier frames were written: the run
    stops with the message, and every file it wrote is removed again."""
    blocker = tmp_path / "out" / ".s_0003.vtu.partial"  # the temporary name of frame 3
    blocker.mkdir(parents=True)
    (blocker / "keep").write_text("not the program's")
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                 ["--frames", str(FRAMES), "--output", "out/s.pvd", "--stats", "out/s.json"] +
                 FAST, tmp_path)
    assert result.returncode == 1
    assert "cannot write" in result.stderr and "s_0003.vtu" in result.stderr
    assert all_files(tmp_path) == ["out/.s_0003.vtu.partial/keep"]


def test_a_collection_that_cannot_be_written_is_named_with_a_hint(tmp_path):
    """The .pvd, written after its frames, fails: the run names it as asked for (not its
    hidden temporary name), says what to check, and leaves none of its frames."""
    blocker = tmp_path / "out" / ".s.pvd.partial"
    blocker.mkdir(parents=True)
    (blocker / "keep").write_text("not the program's")
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                 ["--frames", str(FRAMES), "--output", "out/s.pvd"] + FAST, tmp_path)
    assert result.returncode == 1
    assert "cannot write the collection 'out/s.pvd': check the disk space" in result.stderr, \
        result.stderr
    assert all_files(tmp_path) == ["out/.s.pvd.partial/keep"]


def test_a_commit_that_fails_halfway_keeps_the_earlier_series_whole(tmp_path):
    """Frame 3's name is taken by a folder when a second run commits: the frames renamed
    before it step back, and the earlier series is left as it was, byte for byte (renamed one
    after another, the new run's first frames stood beside the earlier run's .pvd)."""
    args = ["--scene", SCENE, "--light", LIGHT] + PATH + ["--frames", str(FRAMES),
                                                          "--output", "out/s.pvd"] + FAST
    assert run(args, tmp_path).returncode == 0
    out = tmp_path / "out"
    (out / "s_0003.vtu").unlink()
    (out / "s_0003.vtu").mkdir()
    (out / "s_0003.vtu" / "keep").write_text("not the program's")
    earlier = {f.name: f.read_bytes() for f in out.iterdir() if f.is_file()}
    result = run(args + ["--seed", "5"], tmp_path)
    assert result.returncode == 1
    assert "the earlier files are kept, nothing was written" in result.stderr, result.stderr
    assert {f.name: f.read_bytes() for f in out.iterdir() if f.is_file()} == earlier
    assert sorted(all_files(tmp_path)) == sorted(["out/" + name for name in earlier] +
                                                 ["out/s_0003.vtu/keep"])


def test_the_next_run_removes_what_a_killed_run_left(tmp_path):
    """A run killed by SIGKILL (or the out-of-memory killer) cannot clean up: its staged frames
    (.s_0007.vtu.partial) and the earlier frames it had set aside (.s_0001.vtu.earlier) stay.
    The next run of the series removes them when it commits, and only them: not the files of
    another series, nor those newer than the run (another run writing the series now)."""
    out = tmp_path / "out"
    out.mkdir()
    left = [".s_0001.vtu.earlier", ".s_0007.vtu.partial", ".s_0012.vtu.partial"]
    others = [".notes.partial", ".s_extra.vtu.partial", ".t_0001.vtu.partial", "s_0001.vtu.partial",
              ".s_0009.vtu.partial"]
    for name in left + others:
        (out / name).write_text("left over")
    later = time.time() + 3600
    os.utime(out / ".s_0009.vtu.partial", (later, later))
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                 ["--frames", "2", "--output", "out/s.pvd"] + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    assert sorted(all_files(out)) == sorted(["s.pvd", "s_0000.vtu", "s_0001.vtu"] + others)


def test_xvfb_that_cannot_start_fails_the_run_with_its_message(tmp_path):
    env, pids = fake_xvfb(tmp_path, server="sh -c 'echo \"Fatal server error: no screens\" >&2; exit 1'")
    result = run(["--scene", SCENE, "--light", LIGHT, "--output", "out/s.pvd", "--png", "png",
                  "--frames", "2"] + PATH + FAST, tmp_path, env=env)
    assert result.returncode == 1
    assert "--png: Xvfb did not start" in result.stderr and "no screens" in result.stderr
    assert len(started_pids(pids)) == 20  # one display number after another
    assert [f for f in all_files(tmp_path) if not f.startswith("bin/")] == ["xvfb.pids"]

"""The command line under mpiexec: the ranks solve together (with chunks each rank takes whole
chunks and streams their frames) and each writes the frames it holds; the series is the one
process's, bit for bit. A usage error is reported once and writes nothing; an interrupt in the
middle of the solve leaves no file and no process behind.

ctest sets MLR_CLI, MLR_DATA_DIR and MLR_MPIEXEC; by hand:
    MLR_CLI=build/bin/moving-light-radiosity MLR_MPIEXEC=mpiexec \\
        /usr/bin/python3 -m pytest Testing/Parallel/test_cli_ranks.py
"""
import json
import os
import signal
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from cli_support import CLI, FAST, LIGHT, SCENE, all_files, lines_until, run  # noqa: E402

from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader  # noqa: E402
import numpy  # noqa: E402
import pytest  # noqa: E402

MPIEXEC = [os.environ.get("MLR_MPIEXEC", "mpiexec"), "--allow-run-as-root", "--oversubscribe"]
PATH = ["--from", "0.15,0.5478,0.15", "--to", "0.40,0.5478,0.40"]
COMMON = ["--scene", SCENE, "--light", LIGHT] + PATH + FAST + ["--threads", "1"]


def run_ranks(ranks, args, cwd, timeout=240):
    return subprocess.run(MPIEXEC + ["-n", str(ranks), CLI] + args, cwd=cwd, capture_output=True,
                          text=True, timeout=timeout)


def arrays(path):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    data = reader.GetOutput()
    out = {"points": vtk_to_numpy(data.GetPoints().GetData())}
    for kind, attributes in (("cell", data.GetCellData()), ("point", data.GetPointData())):
        for i in range(attributes.GetNumberOfArrays()):
            out[kind + " " + attributes.GetArrayName(i)] = vtk_to_numpy(attributes.GetArray(i))
    return out


def assert_same_series(one, many, frames):
    """Every frame's arrays equal bit for bit, the display's Color included (streamed, every
    rank takes the first chunk's exposure, as one process does)."""
    assert sorted(f for f in all_files(one) if f.endswith(".vtu")) == \
        sorted(f for f in all_files(many) if f.endswith(".vtu"))
    assert len([f for f in all_files(many) if f.endswith(".vtu")]) == frames
    assert (one / "s.pvd").read_text() == (many / "s.pvd").read_text()
    for f in range(frames):
        a, b = arrays(one / f"s_{f:04d}.vtu"), arrays(many / f"s_{f:04d}.vtu")
        assert sorted(a) == sorted(b), f
        assert "cell Radiosity" in a and "cell RadiosityStdError" in a
        assert "cell Color" in a
        for name in a:
            assert a[name].shape == b[name].shape and numpy.array_equal(a[name], b[name]), \
                (f, name)


@pytest.mark.parametrize("ranks,per_chunk,overlap", [(2, 4, 0), (3, 4, 0), (3, 6, 0), (2, 6, 3)])
def test_ranks_with_chunks_write_the_serial_series(tmp_path, ranks, per_chunk, overlap):
    # 12 frames in chunks of 4: with 2 ranks rank 0 solves chunks 1 and 3, with 3 one each,
    # each rank streaming its own. In chunks of 6, fewer than the 3 ranks: they split the
    # paths, every rank gets every frame, rank 0 writes them. In chunks of 6 overlapping by
    # 3 (every frame blended), each of 2 ranks solves 9 positions and finishes the seam's
    # frames it holds with the other's.
    args = COMMON + ["--frames", "12", "--frames-per-chunk", str(per_chunk), "--chunk-overlap",
                     str(overlap)]
    one = run(args + ["--output", "one/s.pvd", "--stats", "one/s.json"], tmp_path)
    assert one.returncode == 0, one.stderr
    many = run_ranks(ranks, args + ["--output", "many/s.pvd", "--stats", "many/s.json"],
                     tmp_path)
    assert many.returncode == 0, many.stdout + many.stderr
    assert many.stdout.count("wrote many/s.pvd and 12 frames") == 1, many.stdout
    assert_same_series(tmp_path / "one", tmp_path / "many", 12)
    stats = json.loads((tmp_path / "many/s.json").read_text())
    assert stats["statistics"]["Chunks"] == 12 // per_chunk
    assert stats["statistics"]["ChunkOverlap"] == (overlap or per_chunk // 8 or 1)
    assert stats["statistics"]["Frames"] == 12
    # The light's place in every frame, whichever rank wrote it.
    one_stats = json.loads((tmp_path / "one/s.json").read_text())
    assert stats["frames"] == one_stats["frames"]
    # Every frame's error figures, from the rank that solved it, and the worst on the summary.
    assert stats["errorEstimate"] == one_stats["errorEstimate"]
    error_line = [line for line in one.stdout.splitlines() if line.startswith("relative error")]
    assert len(error_line) == 1 and many.stdout.count(error_line[0]) == 1, many.stdout
    assert all_files(tmp_path / "many") == sorted(
        ["s.json", "s.pvd"] + [f"s_{f:04d}.vtu" for f in range(12)])


def test_ranks_without_chunks_write_the_serial_series(tmp_path):
    # One chunk: the ranks share the paths, every rank holds every frame, rank 0 writes them.
    args = COMMON + ["--frames", "5"]
    one = run(args + ["--output", "one/s.pvd"], tmp_path)
    assert one.returncode == 0, one.stderr
    many = run_ranks(2, args + ["--output", "many/s.pvd"], tmp_path)
    assert many.returncode == 0, many.stdout + many.stderr
    assert_same_series(tmp_path / "one", tmp_path / "many", 5)


def test_a_usage_error_is_reported_once_and_writes_nothing(tmp_path):
    result = run_ranks(2, ["--frames", "3", "--output", "u/s.pvd"], tmp_path)
    assert result.returncode == 2
    assert result.stderr.count("--frames needs --from and --to") == 1, result.stderr
    result = run_ranks(2, COMMON + ["--frames", "3", "--png", "pictures", "--output", "p/s.pvd"],
                       tmp_path)
    assert result.returncode == 2
    assert result.stderr.count("--png under mpiexec") == 1, result.stderr
    assert all_files(tmp_path) == []


def test_an_interrupt_in_the_second_round_of_chunks_leaves_nothing(tmp_path):
    process = subprocess.Popen(
        MPIEXEC + ["-n", "2", CLI] + ["--scene", SCENE, "--light", LIGHT] + PATH +
        ["--frames", "16", "--frames-per-chunk", "4", "--paths", "3000000", "--patch-size",
         "0.08", "--threads", "1", "--output", "out/s.pvd"],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True)
    try:
        seen = lines_until(process, "chunk 3 of 4", 200)  # rank 0 solves chunks 1 and 3
        assert any("chunk 3 of 4" in line for line in seen), (seen, process.poll())
        assert process.poll() is None, "the run ended before it was interrupted"
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    assert process.returncode != 0
    assert "interrupted: nothing was written" in err, err
    assert all_files(tmp_path) == []
    # No rank outlives the job.
    left = subprocess.run(["pgrep", "-f", "--", str(tmp_path / "out")], capture_output=True,
                          text=True)
    assert left.stdout == "", left.stdout


def series_files(folder):
    return {f: (folder / f).read_bytes() for f in all_files(folder)}


def test_a_rename_failing_on_one_rank_keeps_the_earlier_series_whole(tmp_path):
    """A folder where rank 0's frame 9 goes makes its rename fail after rank 1 could have
    renamed its own: every rank moves back, and the earlier series is as it was."""
    earlier = run_ranks(1, COMMON + ["--frames", "6", "--output", "out/s.pvd"], tmp_path)
    assert earlier.returncode == 0, earlier.stderr
    (tmp_path / "out" / "s_0009.vtu").mkdir()
    before = series_files(tmp_path / "out")
    # Chunks of 4 over 12 frames: rank 0 solves frames 0-3 and 8-11, rank 1 frames 4-7.
    result = run_ranks(2, COMMON + ["--frames", "12", "--frames-per-chunk", "4", "--output",
                                    "out/s.pvd"], tmp_path)
    assert result.returncode == 1
    assert "the earlier files are kept, nothing was written" in result.stderr, result.stderr
    assert series_files(tmp_path / "out") == before
    assert sorted(os.listdir(tmp_path / "out")) == sorted(
        [f"s_{f:04d}.vtu" for f in range(6)] + ["s.pvd", "s_0009.vtu"])


def test_ranks_whose_folders_differ_are_refused(tmp_path):
    """Rank 0's index would name frames another rank wrote where it cannot see them."""
    args = [CLI] + COMMON + ["--frames", "8", "--frames-per-chunk", "4", "--output", "out/s.pvd"]
    for rank in ("a", "b"):
        (tmp_path / rank).mkdir()
    result = subprocess.run(MPIEXEC + ["-n", "1", "-wdir", str(tmp_path / "a")] + args +
                            [":", "-n", "1", "-wdir", str(tmp_path / "b")] + args,
                            capture_output=True, text=True, timeout=240)
    assert result.returncode == 1
    assert "rank 0 does not see 'out/s_00" in result.stderr and "which another rank wrote" in \
        result.stderr
    assert all_files(tmp_path) == []

"""The command line's error estimate: --error-batches writes RadiosityStdError (cells and points)
and the per-frame relative error into every frame and reports it, --target-error adds rounds
until the lit elements' p95 is at most the target, and bad values are refused by name.

ctest sets MLR_CLI (the executable) and MLR_DATA_DIR (Data/).
"""
import json
import os
import sys
import xml.etree.ElementTree as ElementTree

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from cli_support import FAST, LIGHT, SCENE, all_files, run  # noqa: E402

from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

PATH = ["--from", "0.15,0.5478,0.15", "--to", "0.40,0.5478,0.40", "--frames", "2"]


def frames(directory, collection="out/e.pvd"):
    grids = []
    for dataset in ElementTree.parse(directory / collection).findall(".//DataSet"):
        reader = vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(directory / "out" / dataset.get("file")))
        reader.Update()
        grids.append(reader.GetOutput())
    return grids


def values(grid, name):
    array = grid.GetFieldData().GetAbstractArray(name)
    return [array.GetValue(i) for i in range(array.GetNumberOfValues())]


def test_error_batches_write_standard_errors_and_report_them(tmp_path):
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH + FAST +
                 ["--error-batches", "4", "--output", "out/e.pvd", "--stats", "out/e.json"],
                 tmp_path)
    assert result.returncode == 0, result.stderr
    assert "relative error of the lit elements: median" in result.stdout, result.stdout
    assert "4 batches in 1 round, stopped by batches" in result.stdout, result.stdout
    grids = frames(tmp_path)
    assert len(grids) == 2
    stats = json.loads((tmp_path / "out" / "e.json").read_text())
    for frame, grid in enumerate(grids):
        cells = grid.GetCellData().GetArray("RadiosityStdError")
        points = grid.GetPointData().GetArray("RadiosityStdError")
        assert cells is not None and points is not None
        assert cells.GetNumberOfComponents() == 3
        assert 0 < cells.GetRange(-1)[1] < grid.GetCellData().GetArray("Radiosity").GetRange(-1)[1]
        # Each frame's file holds its own figures (a year's in every file grew the series as
        # the square of its frames: QA), the --stats file every frame's.
        p95 = values(grid, "RelativeErrorP95")
        median = values(grid, "RelativeErrorMedian")
        assert p95 == [stats["errorEstimate"]["RelativeErrorP95"][frame]]
        assert median == [stats["errorEstimate"]["RelativeErrorMedian"][frame]]
        assert values(grid, "LitElements") == [stats["errorEstimate"]["LitElements"][frame]]
        assert all(0 < m <= p < 1 for m, p in zip(median, p95))
        assert values(grid, "StoppedBy") == ["batches"]
    assert stats["settings"]["errorBatches"] == 4
    assert stats["statistics"]["ErrorBatches"] == 4
    assert len(stats["errorEstimate"]["RelativeErrorP95"]) == 2


def test_one_batch_writes_no_error_arrays(tmp_path):
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH + FAST +
                 ["--error-batches", "1", "--output", "out/e.pvd"], tmp_path)
    assert result.returncode == 0, result.stderr
    assert "relative error" not in result.stdout
    for grid in frames(tmp_path):
        assert grid.GetCellData().GetArray("RadiosityStdError") is None
        assert grid.GetFieldData().GetArray("RelativeErrorP95") is None


def test_target_error_is_reached_in_every_frame(tmp_path):
    target = 0.08
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH + FAST +
                 ["--target-error", str(target), "--output", "out/e.pvd"], tmp_path)
    assert result.returncode == 0, result.stderr
    assert "stopped by target" in result.stdout, result.stdout
    # The rounds' progress: the memory and time estimates, then each round's error.
    assert "memory estimate" in result.stdout and "take about" in result.stdout, result.stdout
    assert "round 2" in result.stdout, result.stdout
    for grid in frames(tmp_path):
        assert all(p <= target for p in values(grid, "RelativeErrorP95"))
        assert values(grid, "StoppedBy") == ["target"]
        assert values(grid, "ErrorBatches")[0] > 16


def test_every_chunk_prints_the_round_that_reached_the_target(tmp_path):
    """Each chunk's last round ends right before the next chunk's first line: both show."""
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH[:-2] + FAST +
                 ["--frames", "4", "--frames-per-chunk", "2", "--target-error", "0.3",
                  "--output", "out/e.pvd"], tmp_path)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("chunk ")]
    assert len(starts) == 2, result.stdout
    for begin, end in zip(starts, starts[1:] + [len(lines)]):
        rounds = [line for line in lines[begin:end] if ", round " in line]
        assert rounds and rounds[-1].endswith(": reached"), result.stdout


@pytest.mark.parametrize("args, message", [
    (["--error-batches", "0"], "--error-batches is 0: give a value from 1 to 4096"),
    (["--error-batches", "5000"], "--error-batches is 5000: give a value from 1 to 4096"),
    (["--target-error", "-0.02"], "--target-error is -0.02: give the relative error"),
    (["--target-error", "nan"], "--target-error needs a number, not 'nan'"),
    (["--target-error", "0.000001"], "--target-error is 1e-06: give the relative error"),
    (["--target-error", "1.5"], "--target-error is 1.5: give the relative error"),
    (["--target-error", "1"], "--target-error is 1: give the relative error"),
    (["--target-error", "0.02", "--error-batches", "1"],
     "--target-error needs an error estimate: give --error-batches 2 or more"),
    (["--target-error", "0.02", "--time-limit", "-1"], "--time-limit is -1: give a number"),
    (["--time-limit", "60"], "--time-limit bounds the rounds of --target-error"),
])
def test_bad_error_options_fail_with_a_message_and_write_nothing(tmp_path, args, message):
    result = run(args + ["--output", "out/x.pvd"], tmp_path)
    assert result.returncode == 2
    assert message in result.stderr, result.stderr
    assert all_files(tmp_path) == []


def test_more_batches_than_paths_fail_before_writing(tmp_path):
    # A bad command line (exit 2) naming both options, given or by default.
    for batches in (["--error-batches", "16"], []):
        result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                     ["--paths", "10"] + batches + ["--output", "out/x.pvd"], tmp_path)
        assert result.returncode == 2
        assert "--paths 10 cannot make 16 error batches" in result.stderr, result.stderr
        assert "--error-batches" in result.stderr, result.stderr
        assert not (tmp_path / "out" / "x.pvd").exists()

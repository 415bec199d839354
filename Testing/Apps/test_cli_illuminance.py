"""The command line's Irradiance and Illuminance: the frames it writes carry them, cells and
points, --luminous-efficacy reaches the filter, and a bad efficacy is refused by name.

ctest sets MLR_CLI (the executable) and MLR_DATA_DIR (Data/); by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps
"""
import os
import sys

import numpy
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from cli_support import FAST, LIGHT, SCENE, all_files, run  # noqa: E402

from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
from vtkmodules.util.numpy_support import vtk_to_numpy

PATH = ["--from", "0.15,0.5478,0.15", "--to", "0.40,0.5478,0.40", "--frames", "2"]
WEIGHTS = numpy.array([0.2126, 0.7152, 0.0722])


def read_grid(path):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def solve(tmp_path, name, extra=()):
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                 ["--output", f"{name}/series.pvd"] + FAST + list(extra), tmp_path)
    assert result.returncode == 0, result.stderr
    return [read_grid(tmp_path / name / f"series_{f:04d}.vtu") for f in range(2)]


def arrays(grid, attributes):
    data = grid.GetCellData() if attributes == "cells" else grid.GetPointData()
    irradiance = data.GetArray("Irradiance")
    illuminance = data.GetArray("Illuminance")
    assert irradiance is not None and illuminance is not None, attributes
    assert irradiance.GetNumberOfComponents() == 3
    assert illuminance.GetNumberOfComponents() == 1
    return vtk_to_numpy(irradiance), vtk_to_numpy(illuminance)


def test_frames_carry_irradiance_and_illuminance_and_the_efficacy(tmp_path):
    default = solve(tmp_path, "default")
    doubled = solve(tmp_path, "doubled", ["--luminous-efficacy", "358"])
    for a, b in zip(default, doubled):
        assert a.GetFieldData().GetArray("LuminousEfficacy").GetValue(0) == 179.0
        assert b.GetFieldData().GetArray("LuminousEfficacy").GetValue(0) == 358.0
        assert b.GetFieldData().GetAbstractArray("IlluminanceUnits").GetValue(0) == \
            "lm/(scene unit)^2"
        for attributes in ("cells", "points"):
            irradiance, lux = arrays(a, attributes)
            irradiance2, lux2 = arrays(b, attributes)
            assert lux.max() > 0
            # The same solve (same seed): the same irradiance, the illuminance twice as much.
            numpy.testing.assert_array_equal(irradiance2, irradiance)
            expected = (358.0 * (irradiance.astype(numpy.float64) @ WEIGHTS)).astype(numpy.float32)
            numpy.testing.assert_allclose(lux2, expected, rtol=1e-6)
            numpy.testing.assert_allclose(lux2, 2 * lux, rtol=1e-6)


@pytest.mark.parametrize("value", ["0", "-5", "684"])
def test_a_bad_efficacy_is_refused_by_name(tmp_path, value):
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                 ["--output", "out/series.pvd", "--luminous-efficacy", value] + FAST, tmp_path)
    assert result.returncode == 2
    assert f"--luminous-efficacy is {value}" in result.stderr, result.stderr
    assert all_files(tmp_path) == []


def test_a_non_number_efficacy_is_refused_by_name(tmp_path):
    result = run(["--luminous-efficacy", "nan"], tmp_path)
    assert result.returncode == 2
    assert "--luminous-efficacy needs a number" in result.stderr, result.stderr


def test_help_names_the_option(tmp_path):
    result = run(["--help"], tmp_path)
    assert "--luminous-efficacy LM_PER_W" in result.stdout

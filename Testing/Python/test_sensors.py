"""Sensors through the filter: a Sensors input of points with Normals over a ground plane
under a sun and a uniform sky, the Sensors output's per-frame Irradiance and Illuminance, their
standard errors and its daylight metrics, the surfaces' radiosity untouched by the sensors, the
thread count without effect, and bad sensors refused by name.

A uniform sky's estimator pi L is the same for every direction, so an up-facing sensor on
open ground reads E_dh exactly (to single precision); the sun adds DNI sin(elevation).
"""
import math
import os
import sys

import numpy
import pytest

from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkFloatArray, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersSources import vtkPlaneSource

from movinglightradiosity import vtkMovingLightRadiosity

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from vtk_messages import recorded  # noqa: E402

EDH = 10.0
DNI = 500.0
# Towards the sun: 45 degrees, the zenith, below the horizon (night for the direct sun).
SUNS = ((1.0, 0.0, 1.0), (0.0, 0.0, 1.0), (1.0, 0.0, -0.2))
HOURS = (8.0, 8.5, 9.0)


def output(source):
    source.Update()
    return source.GetOutput()


def sensors(points, normals, name="Normals"):
    data = vtkPolyData()
    pts = vtkPoints()
    for p in points:
        pts.InsertNextPoint(*p)
    data.SetPoints(pts)
    if normals is not None:
        array = vtkFloatArray()
        array.SetName(name)
        array.SetNumberOfComponents(3)
        for n in normals:
            array.InsertNextTuple3(*n)
        data.GetPointData().AddArray(array)
    return data


def trajectory():
    data = vtkPolyData()
    pts = vtkPoints()
    for s in SUNS:
        pts.InsertNextPoint(*s)
    data.SetPoints(pts)
    time = vtkDoubleArray()
    time.SetName("Time")
    for t in HOURS:
        time.InsertNextValue(t)
    data.GetPointData().AddArray(time)
    # Each frame's own diffuse irradiance, as a weather file gives it: used as given, twilight
    # included, where the constant SkyDiffuseHorizontal is dark under a sun below the horizon.
    diffuse = vtkDoubleArray()
    diffuse.SetName("SkyDiffuseHorizontal")
    for _ in HOURS:
        diffuse.InsertNextValue(EDH)
    data.GetPointData().AddArray(diffuse)
    return data


def ground():
    """A 2 x 2 ground of 4 x 4 quads about the origin, facing up."""
    plane = vtkPlaneSource()
    plane.SetOrigin(-1, -1, 0)
    plane.SetPoint1(1, -1, 0)
    plane.SetPoint2(-1, 1, 0)
    plane.SetResolution(4, 4)
    return output(plane)


def make_filter(sensor_data, threads=2):
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(ground())
    radiosity.SetTrajectoryData(trajectory())
    radiosity.SetLightTypeToDirectional()
    radiosity.SetSunIrradiance(DNI)
    radiosity.SetSkyModel(vtkMovingLightRadiosity.UNIFORM_SKY)
    radiosity.SetSkyDiffuseHorizontal(EDH)
    radiosity.SetNumberOfPaths(20000)
    radiosity.SetPatchSize(0.5)
    radiosity.SetNumberOfThreads(threads)
    if sensor_data is not None:
        radiosity.SetSensorsData(sensor_data)
    return radiosity


UP = [(0.2, 0.1, 0.8), (-0.5, 0.3, 0.01), (0.0, 0.0, 0.4)]
UP_NORMALS = [(0, 0, 1), (0, 0, 5), (0, 0, 1)]


@pytest.fixture(scope="module")
def run():
    return make_filter(sensors(UP, UP_NORMALS))


def test_sensors_read_the_sun_and_the_sky(run):
    assert run.GetNumberOfOutputPorts() == 4
    assert run.GetNumberOfInputPorts() == 4
    for frame, t in enumerate(HOURS):
        assert run.UpdateTimeStep(t)
        out = run.GetOutput(vtkMovingLightRadiosity.SENSORS_OUTPUT_PORT)
        assert out.GetNumberOfPoints() == 3
        assert out.GetNumberOfVerts() == 3
        irradiance = vtk_to_numpy(out.GetPointData().GetArray("Irradiance"))
        lux = vtk_to_numpy(out.GetPointData().GetArray("Illuminance"))
        s = SUNS[frame]
        sine = max(0.0, s[2] / math.sqrt(sum(c * c for c in s)))
        expected = EDH + DNI * sine
        efficacy = out.GetFieldData().GetArray("LuminousEfficacy").GetValue(0)
        for i in range(3):
            assert irradiance[i][1] == pytest.approx(expected, rel=1e-5), (frame, i)
            luminance = 0.2126 * irradiance[i][0] + 0.7152 * irradiance[i][1] + 0.0722 * irradiance[i][2]
            assert lux[i] == pytest.approx(efficacy * luminance, rel=1e-5)
        normals = vtk_to_numpy(out.GetPointData().GetArray("Normals"))
        assert normals[1][2] == pytest.approx(1.0)


def test_metrics_over_the_time_steps(run):
    assert run.UpdateTimeStep(HOURS[0])
    out = run.GetOutput(vtkMovingLightRadiosity.SENSORS_OUTPUT_PORT)
    data = out.GetPointData()
    lux = []
    for t in HOURS:
        run.UpdateTimeStep(t)
        lux.append(vtk_to_numpy(run.GetOutput(3).GetPointData().GetArray("Illuminance"))[0])
    assert all(e > 2000 for e in lux[:2]) and 100 <= lux[2] <= 2000, lux
    value = lambda name: data.GetArray(name).GetValue(0)
    assert value("DaylightAutonomy") == pytest.approx(1.0)
    assert value("UDIHigh") == pytest.approx(2 / 3)
    assert value("UDIUseful") == pytest.approx(1 / 3)
    assert value("UDILow") == 0
    # Two frames of direct sun, half an hour each (the Time spacing).
    assert value("DirectSunHours") == pytest.approx(1.0)
    run.SetDaylightAutonomyThreshold(lux[2] * 1.01)
    run.UpdateTimeStep(HOURS[0])
    assert run.GetOutput(3).GetPointData().GetArray("DaylightAutonomy").GetValue(0) == pytest.approx(2 / 3)
    run.SetDaylightAutonomyThreshold(300)


def test_the_field_data_counts_the_sensors_rays(run):
    assert run.UpdateTimeStep(HOURS[0])
    for port in (0, vtkMovingLightRadiosity.SENSORS_OUTPUT_PORT):
        data = run.GetOutput(port).GetFieldData()
        # One shadow ray towards the sun per sensor and frame above its horizon (two of the
        # three), the hemisphere rays once for all frames.
        assert data.GetArray("SensorShadowRays").GetValue(0) == 3 * 2
        assert data.GetArray("SensorGatheringRays").GetValue(0) == 3 * run.GetSensorRays()
        assert data.GetArray("SecondsSensors").GetValue(0) >= 0


def test_sensors_change_no_radiosity_bit_for_bit(run):
    plain = make_filter(None)
    for t in HOURS:
        assert plain.UpdateTimeStep(t) and run.UpdateTimeStep(t)
        a = vtk_to_numpy(plain.GetOutput(0).GetCellData().GetArray("Radiosity"))
        b = vtk_to_numpy(run.GetOutput(0).GetCellData().GetArray("Radiosity"))
        assert a.tobytes() == b.tobytes()
    assert plain.GetOutput(3).GetNumberOfPoints() == 0


def test_thread_count_changes_no_sensor_bit():
    # A wall beside the sensors' line of sight gives the hemisphere rays something to hit.
    points = [(0.3 * i - 0.6, 0.1, 0.3) for i in range(5)]
    normals = [(1, 0.2 * i, 0.5) for i in range(5)]
    one = make_filter(sensors(points, normals), threads=1)
    three = make_filter(sensors(points, normals), threads=3)
    for t in HOURS:
        assert one.UpdateTimeStep(t) and three.UpdateTimeStep(t)
        for name in ("Irradiance", "Illuminance", "IrradianceStdError", "IlluminanceStdError",
                     "DirectSunHours", "UDIHigh"):
            a = vtk_to_numpy(one.GetOutput(3).GetPointData().GetArray(name))
            b = vtk_to_numpy(three.GetOutput(3).GetPointData().GetArray(name))
            assert a.tobytes() == b.tobytes(), name


def test_standard_errors_come_as_the_elements_do():
    # Sensors tilted towards the lit ground read its solution, whose noise they report with
    # their own: with ErrorBatches (16 by default) every frame has IrradianceStdError (RGB,
    # W/m^2) and IlluminanceStdError (lx, the efficacy times its luminance), as the elements
    # have; with one batch neither.
    points = [(0.3 * i - 0.6, 0.1, 0.3) for i in range(5)]
    normals = [(1, 0.2 * i, 0.5) for i in range(5)]
    radiosity = make_filter(sensors(points, normals))
    assert radiosity.GetErrorBatches() == 16
    for t in HOURS:
        assert radiosity.UpdateTimeStep(t)
        out = radiosity.GetOutput(vtkMovingLightRadiosity.SENSORS_OUTPUT_PORT)
        data = out.GetPointData()
        assert data.GetArray("IrradianceStdError").GetNumberOfComponents() == 3
        assert data.GetArray("IlluminanceStdError").GetNumberOfComponents() == 1
        error = vtk_to_numpy(data.GetArray("IrradianceStdError"))
        lux = vtk_to_numpy(data.GetArray("IlluminanceStdError"))
        irradiance = vtk_to_numpy(data.GetArray("Irradiance"))
        assert error.shape == (5, 3) and lux.shape == (5,)
        assert numpy.all(numpy.isfinite(error)) and numpy.all(error >= 0)
        assert numpy.all(numpy.isfinite(lux)) and numpy.all(lux >= 0)
        assert numpy.all(error < 0.5 * irradiance)
        assert numpy.any(error > 0), "the ground's light has noise"
        efficacy = out.GetFieldData().GetArray("LuminousEfficacy").GetValue(0)
        assert lux == pytest.approx(efficacy * (error @ [0.2126, 0.7152, 0.0722]), rel=1e-5)
        p95 = out.GetFieldData().GetArray("SensorRelativeErrorP95")
        assert p95.GetNumberOfTuples() == len(HOURS)
    radiosity.SetErrorBatches(1)
    assert radiosity.UpdateTimeStep(HOURS[0])
    data = radiosity.GetOutput(3).GetPointData()
    assert data.GetArray("IrradianceStdError") is None
    assert data.GetArray("IlluminanceStdError") is None


@pytest.mark.parametrize(
    "data,words",
    [
        (sensors(UP, None), "no point array Normals"),
        (sensors(UP, [(0, 0, 1), (0, 0, 0), (0, 0, 1)]), "sensor 1 has a zero or non-finite normal"),
        (sensors([(0, 0, 1), (float("nan"), 0, 1)], [(0, 0, 1), (0, 0, 1)]), "sensor 1 has a point"),
        # Too few normals were read past their end, too many accepted silently (QA).
        (sensors(UP, UP_NORMALS[:2]), "Normals has 2 tuples for 3 points"),
        (sensors(UP, UP_NORMALS + [(0, 0, 1)]), "Normals has 4 tuples for 3 points"),
    ],
)
def test_bad_sensors_are_refused_by_name(data, words):
    radiosity = make_filter(data)
    errors = recorded(radiosity, "ErrorEvent")
    assert not radiosity.UpdateTimeStep(HOURS[0])
    assert any(words in e and "Sensors" in e for e in errors), errors
    assert radiosity.GetOutput(0).GetNumberOfCells() == 0
    assert radiosity.GetOutput(3).GetNumberOfPoints() == 0


def test_a_lamps_efficacy_keeps_the_solve_unless_it_turns_lumens_into_watts():
    """A lamp's luminous efficacy only turns its irradiance into lux: changing it solved the
    whole animation again for the same bits (QA). The Illuminance and the sensors' metrics
    are now recomputed from the solve kept. With LightFluxLumens it turns lumens into watts,
    and solves again."""
    path = vtkPolyData()
    points = vtkPoints()
    for x in (-0.3, 0.0, 0.3):
        points.InsertNextPoint(x, 0, 1)
    path.SetPoints(points)
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(ground())
    radiosity.SetTrajectoryData(path)
    radiosity.SetLightTypeToPoint()
    radiosity.SetLightPower(20, 20, 20)
    radiosity.SetNumberOfPaths(4000)
    radiosity.SetPatchSize(0.5)
    radiosity.SetSensorsData(sensors(UP, UP_NORMALS))

    def read(step):
        assert radiosity.UpdateTimeStep(float(step))
        out = radiosity.GetOutput(vtkMovingLightRadiosity.SENSORS_OUTPUT_PORT)
        data = out.GetPointData()
        return (vtk_to_numpy(data.GetArray("Irradiance")).copy(),
                vtk_to_numpy(data.GetArray("Illuminance")).copy(),
                vtk_to_numpy(data.GetArray("DaylightAutonomy")).copy(),
                vtk_to_numpy(radiosity.GetOutput(0).GetCellData().GetArray("Illuminance")).copy())

    before = [read(step) for step in range(3)]
    solves = radiosity.GetSolveCount()
    # A threshold between the sensors' lowest lux at 179 and half of it: the autonomy over the
    # three steps falls where a sensor's lux at half the efficacy goes under it.
    lux = numpy.array([b[1] for b in before])
    radiosity.SetDaylightAutonomyThreshold(float(lux.min()) * 0.75)
    assert all(a == pytest.approx(1.0) for a in read(0)[2])
    radiosity.SetLuminousEfficacy(179 / 2)
    after = [read(step) for step in range(3)]
    assert radiosity.GetSolveCount() == solves
    for b, a in zip(before, after):
        assert numpy.array_equal(a[0], b[0])
        numpy.testing.assert_allclose(a[1], b[1] / 2, rtol=1e-6)
        numpy.testing.assert_allclose(a[3], b[3] / 2, rtol=1e-6)
    autonomy = (lux / 2 >= lux.min() * 0.75).mean(axis=0)
    numpy.testing.assert_allclose(after[0][2], autonomy)
    assert autonomy.min() < 1

    # Lumens into watts: the light's power changes, and the solve with it.
    radiosity.SetLightFluxLumens(2000)
    read(0)
    solves = radiosity.GetSolveCount()
    watts = read(0)[0]
    radiosity.SetLuminousEfficacy(179)
    assert numpy.allclose(read(0)[0], watts / 2, rtol=1e-5)
    assert radiosity.GetSolveCount() == solves + 1

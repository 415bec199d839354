"""The sky from Python: a Perez sky following three suns with per-frame Trajectory arrays
SkyDiffuseHorizontal and DirectNormalIrradiance, with no direct sun (SunIrradiance 0); an open
ground gets rho E_dh in each frame, and its Illuminance the Perez efficacy of that frame.

A path reaches the 1 m ground with probability q of at least 0.3 (its disc has the area
pi R^2, R = 0.71 m, and the sky's integral is within 1.5 E_dh for these skies), so 50,000
paths give a relative standard deviation below 0.7 %; reuse spreads the weights over the
mixture of the frames' skies, and the tolerance is six such deviations.
"""
import math
import os
import sys

import pytest

from vtkmodules.vtkCommonCore import vtkDoubleArray
from vtkmodules.vtkFiltersSources import vtkLineSource, vtkPlaneSource

from movinglightradiosity import vtkMovingLightRadiosity

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from vtk_messages import recorded  # noqa: E402

PATHS = 50000
EDH = (50.0, 100.0, 150.0)
DNI = (300.0, 600.0, 0.0)
TOLERANCE = 6 * math.sqrt(0.7 / (PATHS * 0.3))


def output(source):
    source.Update()
    return source.GetOutput()


def point_array(name, values):
    array = vtkDoubleArray()
    array.SetName(name)
    for value in values:
        array.InsertNextValue(value)
    return array


def field(data, name):
    return data.GetFieldData().GetArray(name).GetValue(0)


@pytest.fixture(scope="module")
def sky():
    ground = vtkPlaneSource()
    ground.SetResolution(4, 4)
    directions = vtkLineSource()
    directions.SetPoint1(1, 0, 1)
    directions.SetPoint2(-1, 0.4, 1)
    directions.SetResolution(2)
    trajectory = output(directions)
    trajectory.GetPointData().AddArray(point_array("SkyDiffuseHorizontal", EDH))
    trajectory.GetPointData().AddArray(point_array("DirectNormalIrradiance", DNI))
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(output(ground))
    radiosity.SetTrajectoryData(trajectory)
    radiosity.SetLightTypeToDirectional()
    radiosity.SetSunIrradiance(0)
    radiosity.SetSkyModel(vtkMovingLightRadiosity.PEREZ_SKY)
    radiosity.SetNumberOfPaths(PATHS)
    radiosity.SetPatchSize(0.25)
    radiosity.SetNumberOfThreads(2)
    return radiosity


def test_perez_sky_per_frame_on_open_ground(sky):
    assert sky.GetSkyModel() == vtkMovingLightRadiosity.PEREZ_SKY
    assert sky.GetUp() == (0.0, 0.0, 1.0)
    efficacies = []
    for frame, edh in enumerate(EDH):
        assert sky.UpdateTimeStep(float(frame))
        elements = sky.GetOutput(0)
        direct = elements.GetCellData().GetArray("DirectRadiosity")
        irradiance = elements.GetCellData().GetArray("Irradiance")
        lux = elements.GetCellData().GetArray("Illuminance")
        total = area = 0.0
        efficacy = field(elements, "LuminousEfficacy")
        for cell in range(elements.GetNumberOfCells()):
            a = elements.GetCell(cell).ComputeArea()
            total += a * direct.GetComponent(cell, 1)
            area += a
            e = irradiance.GetTuple3(cell)
            luminance = 0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]
            assert lux.GetValue(cell) == pytest.approx(efficacy * luminance, rel=1e-5, abs=1e-3)
        assert total / area == pytest.approx(0.5 * edh, rel=TOLERANCE), frame
        assert 90 < efficacy < 160
        efficacies.append(efficacy)
    # The efficacy follows each frame's sky (clearness and brightness differ).
    assert len(set(efficacies)) == 3


def test_a_clear_sky_without_a_sun_is_refused():
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(output(vtkPlaneSource()))
    radiosity.SetSkyModel(vtkMovingLightRadiosity.CIE_CLEAR_SKY)
    radiosity.SetNumberOfThreads(2)
    errors = recorded(radiosity, "ErrorEvent")
    assert not radiosity.UpdateTimeStep(0.0)
    assert any("follows the sun: set LightType to Directional" in e for e in errors), errors
    assert radiosity.GetOutput(0).GetNumberOfCells() == 0


def test_a_sky_with_a_lamp_is_refused_not_dropped():
    # The lamp used to be left out of the solve without a word; the sky alone and the sun
    # with a sky solve.
    lamp = vtkPlaneSource()
    lamp.SetOrigin(-0.1, -0.1, 1)
    lamp.SetPoint1(-0.1, 0.1, 1)
    lamp.SetPoint2(0.1, -0.1, 1)
    for light_type, with_lamp in ((vtkMovingLightRadiosity.AREA_LIGHT, True),
                                  (vtkMovingLightRadiosity.POINT_LIGHT, False)):
        radiosity = vtkMovingLightRadiosity()
        radiosity.SetSceneData(output(vtkPlaneSource()))
        if with_lamp:
            radiosity.SetLightData(output(lamp))
        radiosity.SetLightType(light_type)
        radiosity.SetSkyModel(vtkMovingLightRadiosity.UNIFORM_SKY)
        radiosity.SetNumberOfThreads(2)
        errors = recorded(radiosity, "ErrorEvent")
        assert not radiosity.UpdateTimeStep(0.0)
        assert any("a sky lights the scene alone or with the sun" in e for e in errors), errors


def test_a_gltf_scene_under_a_z_up_sky_is_warned_of():
    # glTF is Y-up: a scene read from it (field data SceneFormat "glTF") under a sky whose Up
    # is still the default +z gets a warning naming Up; with Up +y it gets none.
    from vtkmodules.vtkCommonCore import vtkStringArray
    ground = output(vtkPlaneSource())
    format_array = vtkStringArray()
    format_array.SetName("SceneFormat")
    format_array.InsertNextValue("glTF")
    ground.GetFieldData().AddArray(format_array)
    for up, warned in (((0.0, 0.0, 1.0), True), ((0.0, 1.0, 0.0), False)):
        radiosity = vtkMovingLightRadiosity()
        radiosity.SetSceneData(ground)
        radiosity.SetSkyModel(vtkMovingLightRadiosity.UNIFORM_SKY)
        radiosity.SetUp(*up)
        radiosity.SetNumberOfPaths(2000)
        radiosity.SetNumberOfThreads(2)
        warnings = recorded(radiosity, "WarningEvent")
        assert radiosity.UpdateTimeStep(0.0)
        assert any("read from glTF, which is Y-up, but Up is +z" in w for w in warnings) == warned, \
            warnings


def test_an_unknown_light_type_or_sky_model_is_named():
    # Kept as given, not clamped to the nearest kind, so that the error names what was given.
    for setter, value, message in (("SetLightType", 7, "LightType is 7: give 0 (Area)"),
                                   ("SetSkyModel", 9, "SkyModel is 9: give 0 (none)")):
        radiosity = vtkMovingLightRadiosity()
        radiosity.SetSceneData(output(vtkPlaneSource()))
        getattr(radiosity, setter)(value)
        errors = recorded(radiosity, "ErrorEvent")
        assert not radiosity.UpdateTimeStep(0.0)
        assert any(message in e for e in errors), errors

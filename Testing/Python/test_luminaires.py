"""Luminaires from Python: a point light without a Light input, spots on area and point
lights, lumens, and the refusal of contradictory settings with messages naming them.

Run by ctest with PYTHONPATH set to the build's Python folder (see CMakeLists.txt), or by hand:
    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 -m pytest Testing/Python
"""
import math

from vtkmodules.vtkFiltersCore import vtkCellCenters
from vtkmodules.vtkFiltersSources import vtkPlaneSource
from vtkmodules.util.misc import calldata_type
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.util.vtkConstants import VTK_STRING

from movinglightradiosity import vtkMovingLightRadiosity

from test_rigs_and_sun import field, output, square_light


def floor(half=2.0, cells=20):
    """A square floor at z = 0 facing up."""
    plane = vtkPlaneSource()
    plane.SetOrigin(-half, -half, 0)
    plane.SetPoint1(half, -half, 0)
    plane.SetPoint2(-half, half, 0)
    plane.SetResolution(cells, cells)
    return output(plane)


def radiosity_filter(**properties):
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(floor())
    radiosity.SetNumberOfPaths(40000)
    radiosity.SetNumberOfThreads(2)
    radiosity.SetPathStart(0, 0, 1)
    radiosity.SetPathEnd(1, 0, 1)
    radiosity.SetNumberOfPositions(2)
    for name, value in properties.items():
        getattr(radiosity, "Set" + name)(*value if isinstance(value, tuple) else (value,))
    return radiosity


def direct(radiosity, time):
    radiosity.UpdateTimeStep(time)
    elements = radiosity.GetOutput(0)
    centres = vtkCellCenters()
    centres.SetInputData(elements)
    centres.Update()
    xyz = vtk_to_numpy(centres.GetOutput().GetPoints().GetData())
    values = vtk_to_numpy(elements.GetCellData().GetArray("DirectRadiosity"))[:, 1]
    return xyz, values, elements


def test_point_light_needs_no_light_input_and_moves():
    radiosity = radiosity_filter(LightType=vtkMovingLightRadiosity.POINT_LIGHT)
    for time, x in ((0.0, 0.0), (1.0, 1.0)):
        xyz, values, elements = direct(radiosity, time)
        assert field(elements, "LightPosition") == (x, 0.0, 1.0)
        # E = Phi cos^2 / (pi r^2) is symmetric about the point below the light: so is the
        # light on a disc there (0.3% of noise from 10,000 paths).
        near = numpy_hypot(xyz - (x, 0, 0)) < 0.6
        centre = (xyz[near, :2] * values[near, None]).sum(axis=0) / values[near].sum()
        assert math.hypot(centre[0] - x, centre[1]) < 0.05, centre
        assert radiosity.GetOutput(2).GetNumberOfCells() == 0  # no polygons to show


def test_spot_darkens_the_floor_outside_its_cone():
    for light in ("point", "area"):
        kind = dict(LightType=vtkMovingLightRadiosity.POINT_LIGHT) if light == "point" else {}
        radiosity = radiosity_filter(SpotHalfAngle=15.0, **kind)
        plain = radiosity_filter(**kind)
        if light == "area":
            for f in (radiosity, plain):
                f.SetLightData(output(square_light((0, 0, 1), 0.05)))
        xyz, spot, _ = direct(radiosity, 0.0)
        _, lambertian, _ = direct(plain, 0.0)
        outside = numpy_hypot(xyz) > math.tan(math.radians(15.0)) + 0.3
        assert (spot[outside] == 0).all(), light
        assert (lambertian[outside] > 0).any(), light
        # Within the cone the spot is brighter: 1 / (2 pi (1 - cos 15)) against cos / pi.
        below = numpy_hypot(xyz) < 0.1
        assert spot[below].mean() > 10 * lambertian[below].mean(), light


def numpy_hypot(xyz):
    return (xyz[:, 0] ** 2 + xyz[:, 1] ** 2) ** 0.5


def test_lumens_scale_the_power_by_the_efficacy():
    watts = radiosity_filter(LightType=vtkMovingLightRadiosity.POINT_LIGHT)
    lumens = radiosity_filter(LightType=vtkMovingLightRadiosity.POINT_LIGHT,
                              LightFluxLumens=179.0 * 25)
    _, w, _ = direct(watts, 0.0)
    _, lm, _ = direct(lumens, 0.0)
    lit = w > 0
    # 25 W of luminance against the default 100 W white light, along the same paths.
    assert abs((lm[lit] / w[lit]).mean() - 0.25) < 1e-6


def failure(radiosity):
    errors = []

    @calldata_type(VTK_STRING)
    def record(_caller, _event, message):
        errors.append(message)

    radiosity.AddObserver("ErrorEvent", record)
    assert not radiosity.UpdateTimeStep(0.0)
    assert radiosity.GetOutput(0).GetNumberOfCells() == 0
    return " ".join(errors)


def test_contradictory_or_missing_luminaires_are_refused_naming_them(tmp_path):
    point = vtkMovingLightRadiosity.POINT_LIGHT
    both = failure(radiosity_filter(LightType=point, SpotHalfAngle=20.0,
                                    LightDistributionFile=str(tmp_path / "a.ies")))
    assert "LightDistributionFile" in both and "SpotHalfAngle" in both, both
    soft = failure(radiosity_filter(LightType=point, SpotSoftEdge=5.0))
    assert "SpotSoftEdge" in soft, soft
    missing = str(tmp_path / "missing.ldt")
    assert missing in failure(radiosity_filter(LightType=point, LightDistributionFile=missing))


def test_print_self_lists_the_luminaire():
    text = str(radiosity_filter(LightType=vtkMovingLightRadiosity.POINT_LIGHT,
                                SpotHalfAngle=30.0, LightFluxLumens=800.0))
    for line in ("LightType: Point", "SpotHalfAngle: 30 degrees", "SpotSoftEdge: 0 degrees",
                 "LightFluxLumens: 800 lm", "LightDistributionFile: "):
        assert line in text, text

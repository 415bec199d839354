"""Luminaires from Python: a point light without a Light input, spots on area and point
lights, lumens, a luminaire emitting from its file's opening, TILT=INCLUDE factors per frame,
and the refusal of contradictory settings with messages naming them.

Run by ctest with PYTHONPATH set to the build's Python folder (see CMakeLists.txt), or by hand:
    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 -m pytest Testing/Python
"""
import math
import os
import sys

from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData, vtkPolyLine
from vtkmodules.vtkFiltersCore import vtkCellCenters
from vtkmodules.vtkFiltersSources import vtkPlaneSource
from vtkmodules.util.numpy_support import vtk_to_numpy

from movinglightradiosity import vtkMovingLightRadiosity

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from vtk_messages import recorded  # noqa: E402

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
        # The light as solved: one vertex where it is, no polygons to show.
        light = radiosity.GetOutput(2)
        assert (light.GetNumberOfVerts(), light.GetNumberOfPolys()) == (1, 0)
        assert light.GetPoint(0) == (x, 0.0, 1.0)


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
    errors = recorded(radiosity, "ErrorEvent")
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
    for line in ("LightType: 2 (Point)", "SpotHalfAngle: 30 degrees", "SpotSoftEdge: 0 degrees",
                 "LightFluxLumens: 800 lm", "LightDistributionFile: "):
        assert line in text, text


def ies_file(path, opening="0.4 0.8 0", tilt="TILT=NONE"):
    """A uniform 100 cd downlight (LM-63-2002, metres) with the given width, length and height
    of its luminous opening and TILT block."""
    path.write_text("IESNA:LM-63-2002\n[TEST] luminaire\n" + tilt + "\n"
                    f"1 -1 1 3 1 1 2 {opening}\n1 1 20\n0 45 90\n0\n100 100 100\n")
    return str(path)


def warnings_of(radiosity):
    warnings = recorded(radiosity, "WarningEvent")
    return warnings


def polygon_area_and_bounds(light):
    assert light.GetNumberOfCells() == 1
    points = vtk_to_numpy(light.GetPoints().GetData())
    area = 0.0
    for i in range(len(points)):
        a, b = points[i], points[(i + 1) % len(points)]
        area += a[0] * b[1] - a[1] * b[0]
    return abs(area) / 2, light.GetBounds()


def test_luminaire_emits_from_the_files_opening(tmp_path):
    # A 0.8 m (length, C0-C180, x) by 0.4 m (width) opening, centred on the path's points.
    rectangle = radiosity_filter(LightType=vtkMovingLightRadiosity.LUMINAIRE_LIGHT,
                                 LightDistributionFile=ies_file(tmp_path / "troffer.ies"))
    for time, x in ((0.0, 0.0), (1.0, 1.0)):
        rectangle.UpdateTimeStep(time)
        area, bounds = polygon_area_and_bounds(rectangle.GetOutput(2))
        assert abs(area - 0.32) < 1e-9, area
        expected = (x - 0.4, x + 0.4, -0.2, 0.2, 1.0, 1.0)
        assert all(abs(b - e) < 1e-9 for b, e in zip(bounds, expected)), bounds
        _, values, _ = direct(rectangle, time)
        assert values.max() > 0
    # A round one (negative diameters, LM-63-2002): a polygon of the disc's area.
    disc = radiosity_filter(LightType=vtkMovingLightRadiosity.LUMINAIRE_LIGHT,
                            LightDistributionFile=ies_file(tmp_path / "disc.ies", "-0.3 -0.3 0"))
    disc.UpdateTimeStep(0.0)
    area, bounds = polygon_area_and_bounds(disc.GetOutput(2))
    assert abs(area - math.pi * 0.15 ** 2) < 1e-9, area
    assert abs(bounds[1] - bounds[0] - 0.3) < 0.01, bounds
    # No opening: a point light, said so.
    point = radiosity_filter(LightType=vtkMovingLightRadiosity.LUMINAIRE_LIGHT,
                             LightDistributionFile=ies_file(tmp_path / "point.ies", "0 0 0"))
    warnings = warnings_of(point)
    point.UpdateTimeStep(0.0)
    assert (point.GetOutput(2).GetNumberOfVerts(), point.GetOutput(2).GetNumberOfPolys()) == (1, 0)
    assert any("gives no luminous opening" in w and "point light" in w for w in warnings), warnings
    # Without a file there is no opening to emit from.
    assert "LightDistributionFile" in failure(
        radiosity_filter(LightType=vtkMovingLightRadiosity.LUMINAIRE_LIGHT))


def test_area_light_of_another_size_than_the_opening_is_warned_of(tmp_path):
    big = radiosity_filter(LightDistributionFile=ies_file(tmp_path / "small.ies", "0.05 0.05 0"))
    big.SetLightData(output(square_light((0, 0, 1), 0.5)))
    warnings = warnings_of(big)
    big.UpdateTimeStep(0.0)
    assert any("luminous opening (a rectangle) is 0.05 by 0.05 m" in w for w in warnings), warnings
    same = radiosity_filter(LightDistributionFile=ies_file(tmp_path / "same.ies", "0.5 0.5 0"))
    same.SetLightData(output(square_light((0, 0, 1), 0.5)))
    warnings = warnings_of(same)
    same.UpdateTimeStep(0.0)
    assert not any("luminous opening" in w for w in warnings), warnings


def test_opening_warnings_come_only_where_the_light_emits_from_the_opening(tmp_path):
    # A rectangle with luminous sides (height 0.1 m) is kept as its bottom rectangle: that
    # concerns the Luminaire light, which emits from it, not the point light, which has no
    # extent. The same for a EULUMDAT file without a luminous area.
    sides = ies_file(tmp_path / "sides.ies", "0.4 0.8 0.1")
    ldt = tmp_path / "body.ldt"
    ldt.write_text("\n".join(
        ["body", "1", "1", "1", "0", "3", "45", "r", "l", "n", "body.ldt", "d", "600", "0", "80",
         "0", "0", "0", "0", "0", "0", "100", "100", "1", "0", "1", "1", "LED", "1000", "3000",
         "1B", "10"] + ["0.5"] * 10 + ["0", "0", "45", "90", "100", "100", "100"]) + "\n")
    for path, words in ((sides, "emitted from its outline seen from below"),
                        (str(ldt), "emits from the luminaire's outline")):
        for light, warned in ((vtkMovingLightRadiosity.POINT_LIGHT, False),
                              (vtkMovingLightRadiosity.LUMINAIRE_LIGHT, True)):
            radiosity = radiosity_filter(LightType=light, LightDistributionFile=path,
                                         NumberOfPaths=2000)
            warnings = warnings_of(radiosity)
            radiosity.UpdateTimeStep(0.0)
            assert any(words in w for w in warnings) == warned, (path, light, warnings)


def two_point_trajectory(normals=None, power=None):
    """(0, 0, 1) then (0.5, 0, 1), with the point arrays Normal and Power when given."""
    points = vtkPoints()
    points.InsertNextPoint(0, 0, 1)
    points.InsertNextPoint(0.5, 0, 1)
    trajectory = vtkPolyData()
    trajectory.SetPoints(points)
    line = vtkPolyLine()
    line.GetPointIds().SetNumberOfIds(2)
    line.GetPointIds().SetId(0, 0)
    line.GetPointIds().SetId(1, 1)
    lines = vtkCellArray()
    lines.InsertNextCell(line)
    trajectory.SetLines(lines)
    for name, tuples in (("Normal", normals), ("Power", power)):
        if tuples is not None:
            array = vtkDoubleArray()
            array.SetName(name)
            array.SetNumberOfComponents(len(tuples[0]))
            for t in tuples:
                array.InsertNextTuple(t)
            trajectory.GetPointData().AddArray(array)
    return trajectory


def test_light_output_carries_the_point_light_as_solved(tmp_path):
    # The command line's --stats took a point light's power from LightPower and its own sums,
    # for the Light output had nothing of it: it now holds the light as solved, in each frame
    # at its place, with its power (lumens of the light's colour, times the TILT factor and
    # the Trajectory's Power) and that power's flux.
    tilt = math.radians(60)
    trajectory = two_point_trajectory(
        normals=[(0, 0, -1), (math.sin(tilt), 0, -math.cos(tilt))], power=[(1,), (0.5,)])
    radiosity = radiosity_filter(
        LightType=vtkMovingLightRadiosity.POINT_LIGHT, LightPower=(2.0, 1.0, 0.0),
        LightFluxLumens=895.0, LightDistributionFile=ies_file(
            tmp_path / "tilt.ies", "0 0 0", "TILT=INCLUDE\n1\n2\n0 90\n1 0.5"))
    radiosity.SetTrajectoryData(trajectory)
    watts = 895.0 / 179.0 / (0.2126 * 2 + 0.7152 * 1)  # per unit of the colour (2, 1, 0)
    for time, position, factor in ((0.0, (0, 0, 1), 1.0),
                                   (1.0, (0.5, 0, 1), (1 - 0.5 * 60 / 90) * 0.5)):
        errors = recorded(radiosity, "ErrorEvent")
        assert radiosity.UpdateTimeStep(time), errors
        light = radiosity.GetOutput(2)
        assert (light.GetNumberOfPoints(), light.GetNumberOfVerts(),
                light.GetNumberOfPolys()) == (1, 1, 0), time
        assert light.GetPoint(0) == position
        assert field(radiosity.GetOutput(0), "LightPosition") == position
        power = light.GetCellData().GetArray("Power").GetTuple3(0)
        expected = (2 * watts * factor, watts * factor, 0.0)
        assert all(abs(p - e) <= 1e-12 * watts for p, e in zip(power, expected)), (power, expected)
        flux = light.GetCellData().GetArray("LuminousFlux").GetValue(0)
        assert abs(flux - 895.0 * factor) < 1e-9, (time, flux)

    # An area light's polygons carry their share of the flux too.
    area = radiosity_filter(LightType=vtkMovingLightRadiosity.LUMINAIRE_LIGHT,
                            LightFluxLumens=895.0,
                            LightDistributionFile=ies_file(tmp_path / "opening.ies"))
    assert area.UpdateTimeStep(0.0)
    cells = area.GetOutput(2).GetCellData()
    assert area.GetOutput(2).GetNumberOfPolys() > 0
    total = sum(cells.GetArray("LuminousFlux").GetValue(c)
                for c in range(cells.GetNumberOfTuples()))
    assert abs(total - 895.0) < 1e-9, total


def test_tilt_include_scales_each_frame_by_its_factor(tmp_path):
    # The same point light, aimed down in frame 0 and tilted 60 degrees in frame 1 (a Normal
    # array), with and without a TILT table of factors 1 at 0 and 0.5 at 90 degrees: the same
    # paths, so frame 1's light is exactly 1 - 0.5 (60 / 90) of the untilted one's, and
    # frame 0's equal.
    tilt = math.radians(60)
    trajectory = two_point_trajectory(normals=[(0, 0, -1), (math.sin(tilt), 0, -math.cos(tilt))])
    # The point light, and the luminaire of the file's 0.4 by 0.8 m opening (an area light).
    for kind in (vtkMovingLightRadiosity.POINT_LIGHT, vtkMovingLightRadiosity.LUMINAIRE_LIGHT):
        runs = {}
        for name, block in (("none", "TILT=NONE"), ("tilt", "TILT=INCLUDE\n1\n2\n0 90\n1 0.5")):
            radiosity = radiosity_filter(LightType=kind,
                                         LightDistributionFile=ies_file(tmp_path / f"{name}.ies",
                                                                        tilt=block))
            radiosity.SetTrajectoryData(trajectory)
            runs[name] = [direct(radiosity, t)[1] for t in (0.0, 1.0)]
        for frame, factor in ((0, 1.0), (1, 1 - 0.5 * 60 / 90)):
            lit = runs["none"][frame] > 0
            assert lit.any()
            ratio = runs["tilt"][frame][lit] / runs["none"][frame][lit]
            # Results are stored to within 2^-10 of themselves (16 bits per channel): each
            # of the 16 error batches, then their mean; a ratio of two is within 4 x 2^-10.
            assert abs(ratio / factor - 1).max() < 4 * 2.0 ** -10, \
                (kind, frame, ratio.min(), ratio.max())
    # Tilted beyond the table: the end factor, with a warning naming the position.
    normals = trajectory.GetPointData().GetArray("Normal")
    normals.SetTuple3(1, 0, 0, 1)  # aimed straight up: 180 degrees
    normals.Modified()
    beyond = radiosity_filter(LightType=vtkMovingLightRadiosity.POINT_LIGHT,
                              LightDistributionFile=ies_file(
                                  tmp_path / "beyond.ies", tilt="TILT=INCLUDE\n1\n2\n0 90\n1 0.5"))
    beyond.SetTrajectoryData(trajectory)
    warnings = warnings_of(beyond)
    beyond.UpdateTimeStep(0.0)
    assert any("light position 1 tilts the luminaire by 180 degrees, outside the TILT table's "
               "0 to 90" in w for w in warnings), warnings

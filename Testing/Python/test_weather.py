"""vtkSunPathSource reading a weather file (Data/paris_synthetic.epw, Data/make_weather.py):
its frames and per-frame arrays, the night left out or kept, a malformed file refused, and
vtkMovingLightRadiosity lit by it with a Perez sky that reads the frames' day of the year.

The open 1 m ground of test_sky.py gets each hour's DNI sin(elevation) + DHI: a path of the
sky reaches it with probability q >= 0.3, so 50,000 paths give a relative standard deviation
below 0.7 % for the sky's share, and the sun's paths reach it at least as often; reuse
spreads the weights over the frames, and the tolerance is six such deviations.
"""
import math
import os
import sys

import pytest

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkFiltersSources import vtkPlaneSource

from movinglightradiosity import vtkMovingLightRadiosity, vtkSunPathSource

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from vtk_messages import recorded  # noqa: E402

DATA = os.environ.get("MLR_DATA_DIR", os.path.join(os.path.dirname(__file__), os.pardir,
                                                   os.pardir, "Data"))
WEATHER = os.path.join(DATA, "paris_synthetic.epw")
PATHS = 50000
TOLERANCE = 6 * math.sqrt(0.7 / (PATHS * 0.3))
JUNE_21 = 171  # days before June 21 in 2023


def epw_hour(month, day, hour):
    """(GHI, DNI, DHI) of the file's hour (1 to 24, ending then)."""
    with open(WEATHER) as f:
        for number, line in enumerate(f, start=1):
            fields = line.split(",")
            if number > 8 and (int(fields[1]), int(fields[2]), int(fields[3])) == (month, day, hour):
                return tuple(float(v) for v in fields[13:16])
    raise KeyError((month, day, hour))


def weather(first=(6, 21), last=(6, 21), hours=(8, 10), night=False):
    source = vtkSunPathSource()
    source.SetWeatherFile(WEATHER)
    source.SetFirstDate(*first)
    source.SetLastDate(*last)
    source.SetHours(*hours)
    source.SetIncludeNight(night)
    return source


def point_array(data, name):
    array = data.GetPointData().GetArray(name)
    assert array is not None, name
    return list(vtk_to_numpy(array))


def test_the_hours_of_a_weather_file_are_the_frames():
    source = weather()
    assert source.GetWeatherFile() == WEATHER
    assert source.GetFirstDate() == (6, 21) and source.GetLastDate() == (6, 21)
    assert source.GetHours() == (8, 10)
    assert not source.GetIncludeNight()
    source.Update()
    path = source.GetOutput()
    assert path.GetNumberOfPoints() == 3 and path.GetNumberOfLines() == 1
    assert point_array(path, "Time") == [JUNE_21 * 24 + h for h in (8, 9, 10)]
    assert point_array(path, "DayOfYear") == [172, 172, 172]
    assert point_array(path, "ClockHour") == [8, 9, 10]
    assert point_array(path, "Power") == [1, 1, 1]
    for k, hour in enumerate((9, 10, 11)):
        ghi, dni, dhi = epw_hour(6, 21, hour)
        assert point_array(path, "DirectNormalIrradiance")[k] == dni
        assert point_array(path, "SkyDiffuseHorizontal")[k] == dhi
        assert point_array(path, "GlobalHorizontalIrradiance")[k] == ghi
        direction = path.GetPoint(k)
        assert math.dist(direction, (0, 0, 0)) == pytest.approx(1, abs=1e-12)
        elevation = point_array(path, "SunElevation")[k]
        assert math.degrees(math.asin(direction[2])) == pytest.approx(elevation, abs=1e-9)
        # The file's GHI is DNI sin(elevation) + DHI at the middle of the hour (its model,
        # with NOAA's solar position, which is within a few hundredths of a degree).
        assert dni * math.sin(math.radians(elevation)) + dhi == pytest.approx(ghi, abs=6)

    # A whole day: the night is left out, or kept with Power 0.
    day = weather(hours=(0, 23))
    day.Update()
    assert 16 <= day.GetOutput().GetNumberOfPoints() <= 17
    day.SetIncludeNight(True)
    day.Update()
    kept = day.GetOutput()
    assert kept.GetNumberOfPoints() == 24
    elevations = point_array(kept, "SunElevation")
    assert point_array(kept, "Power") == [1.0 if e > 0 else 0.0 for e in elevations]


def test_a_malformed_weather_file_is_refused_with_its_line(tmp_path):
    lines = open(WEATHER).read().split("\n")
    lines[20] = lines[20].replace("2023,1,1,", "2023,1,2,", 1)
    bad = tmp_path / "bad.epw"
    bad.write_text("\n".join(lines))
    source = vtkSunPathSource()
    source.SetWeatherFile(str(bad))
    errors = recorded(source, "ErrorEvent")
    source.Update()
    assert any("line 21: gives January 2 hour 13 where January 1 hour 13 belongs" in e
               for e in errors), errors
    assert source.GetOutput().GetNumberOfPoints() == 0


def solve(trajectory):
    ground = vtkPlaneSource()
    ground.SetResolution(4, 4)
    ground.Update()
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(ground.GetOutput())
    radiosity.SetTrajectoryData(trajectory)
    radiosity.SetLightTypeToDirectional()
    radiosity.SetSkyModel(vtkMovingLightRadiosity.PEREZ_SKY)
    radiosity.SetNumberOfPaths(PATHS)
    radiosity.SetPatchSize(0.25)
    radiosity.SetNumberOfThreads(2)
    return radiosity


def mean_irradiance(elements):
    irradiance = elements.GetCellData().GetArray("Irradiance")
    total = area = 0.0
    for cell in range(elements.GetNumberOfCells()):
        a = elements.GetCell(cell).ComputeArea()
        total += a * irradiance.GetComponent(cell, 1)
        area += a
    return total / area


def test_the_filter_takes_the_sun_and_sky_of_each_hour_and_its_date():
    source = weather()
    source.Update()
    trajectory = source.GetOutput()
    radiosity = solve(trajectory)
    efficacies = []
    for k, time in enumerate(point_array(trajectory, "Time")):
        assert radiosity.UpdateTimeStep(float(time))
        elements = radiosity.GetOutput(0)
        dni = point_array(trajectory, "DirectNormalIrradiance")[k]
        dhi = point_array(trajectory, "SkyDiffuseHorizontal")[k]
        sine = math.sin(math.radians(point_array(trajectory, "SunElevation")[k]))
        # The sun's irradiance is the file's DNI, not SunIrradiance (1000 by default).
        assert mean_irradiance(elements) == pytest.approx(dni * sine + dhi, rel=TOLERANCE)
        efficacies.append(elements.GetFieldData().GetArray("LuminousEfficacy").GetValue(0))

    # The same hours dated January 1: the Perez sky's extraterrestrial irradiance is 7 %
    # higher then, its brightness lower, and so the diffuse luminous efficacy differs.
    january = vtkPolyData()
    january.DeepCopy(trajectory)
    days = january.GetPointData().GetArray("DayOfYear")
    for k in range(days.GetNumberOfTuples()):
        days.SetValue(k, 1)
    moved = solve(january)
    for k, time in enumerate(point_array(trajectory, "Time")):
        assert moved.UpdateTimeStep(float(time))
        efficacy = moved.GetOutput(0).GetFieldData().GetArray("LuminousEfficacy").GetValue(0)
        assert efficacy != pytest.approx(efficacies[k], rel=1e-6)
        assert efficacy == pytest.approx(efficacies[k], rel=0.05)

    # A day of the year that does not exist is refused by name.
    days.SetValue(0, 400)
    january.Modified()
    refused = solve(january)
    errors = recorded(refused, "ErrorEvent")
    assert not refused.UpdateTimeStep(0.0)
    assert any("DayOfYear has 400" in e for e in errors), errors


def test_a_sun_path_dates_its_frames_too():
    # 2024 is a leap year: June 21 is day 31 + 29 + 31 + 30 + 31 + 21 = 173, which the Perez
    # sky then takes for its extraterrestrial irradiance.
    source = vtkSunPathSource()
    source.SetStartTime(10)
    source.SetEndTime(12)
    source.SetStepMinutes(60)
    source.Update()
    path = source.GetOutput()
    assert point_array(path, "Time") == [10, 11, 12]
    assert point_array(path, "DayOfYear") == [173, 173, 173]
    assert path.GetPointData().GetArray("DirectNormalIrradiance") is None

"""The command line's weather file: --weather with --dates, --hours and --night on the
synthetic Paris year of Data/ (Data/make_weather.py), the frames it makes (their count and
series times, night left out), an open horizontal roof receiving each hour's
DNI sin(elevation) + DHI, and the bad inputs.

The roof is the open square of test_cli_sky.py: nothing hides its sky or its sun. The sky's
share reaches it with probability q = A / (pi R^2) per path (relative standard deviation
sqrt((1 - q) / (N q))), and a sky that changes over frames reuses the paths of all of them,
whose weights spread: the tolerance on the sky's share is twice SIGMAS of those deviations,
as in test_cli_sky.py. The direct sun's share, DNI sin(elevation), is not drawn from the
sky's paths: the same tolerance on the whole (sun and sky) covers it.

ctest sets MLR_CLI and MLR_DATA_DIR; by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps
"""
import json
import math
import os

import pytest

from test_cli_rigs_and_sun import PATHS, SIGMAS, run, solve
from test_cli_sky import relative_sigma, write_ground

DATA = os.path.abspath(os.environ.get("MLR_DATA_DIR", os.path.join(
    os.path.dirname(__file__), os.pardir, os.pardir, "Data")))
WEATHER = os.path.join(DATA, "paris_synthetic.epw")
JUNE_21 = 171  # days before June 21 in 2023


def epw_hours():
    """{(month, day, hour): (dni, dhi)} of the shipped file (hour 1 to 24, ending then)."""
    hours = {}
    with open(WEATHER) as f:
        for number, line in enumerate(f, start=1):
            if number <= 8:
                continue
            fields = line.split(",")
            hours[(int(fields[1]), int(fields[2]), int(fields[3]))] = (float(fields[14]),
                                                                       float(fields[15]))
    return hours


def test_frames_are_the_chosen_daylight_hours(tmp_path):
    ground = write_ground(tmp_path)
    # June 21 in Paris (UTC+1): the sun rises at 04:47 clock time, so the hours starting at
    # 3 and 4 (middles 03:30, 04:30) are night, 5 and 6 are day.
    frames = solve(tmp_path, ["--scene", ground, "--weather", WEATHER, "--dates", "06-21,06-21",
                              "--hours", "3-6", "--stats", "stats.json"], paths=2000)
    assert [t for t, _ in frames] == [JUNE_21 * 24 + 5, JUNE_21 * 24 + 6]
    assert [f.field("TimeValue") for _, f in frames] == [JUNE_21 * 24 + 5, JUNE_21 * 24 + 6]
    for _, frame in frames:
        assert frame.field("SunElevation") > 0
    stats = json.loads((tmp_path / "stats.json").read_text())
    assert stats["sky"] == "perez"  # --weather implies it
    assert stats["trajectory"] == "weather " + WEATHER

    # --night keeps them: dark to the sun, lit by no sky (the file's DHI is 0 there).
    frames = solve(tmp_path, ["--scene", ground, "--weather", WEATHER, "--dates", "06-21,06-21",
                              "--hours", "3-6", "--night"], paths=2000)
    assert [t for t, _ in frames] == [JUNE_21 * 24 + h for h in (3, 4, 5, 6)]
    for _, frame in frames[:2]:
        assert frame.field("SunElevation") < 0
        assert not frame.cells("Irradiance").any()

    # Over the new year: December 31 first, then January 1, counting on from 8760.
    frames = solve(tmp_path, ["--scene", ground, "--weather", WEATHER, "--dates", "12-31,01-01",
                              "--hours", "11-12"], paths=2000)
    assert [t for t, _ in frames] == [364 * 24 + 11, 364 * 24 + 12, 8760 + 11, 8760 + 12]


def test_a_horizontal_roof_gets_dni_sin_elevation_plus_dhi(tmp_path):
    hours = epw_hours()
    # A clear and a cloudier day of the file (cloud cover 0.0 and 0.5), three hours each.
    frames = solve(tmp_path, ["--scene", write_ground(tmp_path), "--weather", WEATHER,
                              "--dates", "06-20,06-21", "--hours", "9-11"])
    assert len(frames) == 6
    tolerance = 2 * SIGMAS * relative_sigma()
    for time, frame in frames:
        day_of_year, clock_hour = divmod(int(time), 24)
        month, day = (6, day_of_year - 151 + 1)
        dni, dhi = hours[(month, day, clock_hour + 1)]
        elevation = math.radians(frame.field("SunElevation"))
        expected = dni * math.sin(elevation) + dhi
        irradiance = frame.mean("Irradiance", frame.area > 0)
        for channel in irradiance:
            assert channel == pytest.approx(expected, rel=tolerance), (time, dni, dhi)


def test_direct_sun_hours_count_an_hour_per_weather_frame(tmp_path):
    """A weather file's frame is an hour, however far apart the frames chosen are: one noon
    hour on each of 10 days counted 24 hours each (the median spacing), 240 direct-sun hours
    for 10 sunny noons (QA)."""
    from test_cli_sensors import read_sensor_series, write_sensors
    sensors = write_sensors(tmp_path, [(0, 0, 0.1)], [(0, 0, 1)])
    result = run(["--scene", write_ground(tmp_path), "--weather", WEATHER, "--dates",
                  "06-01,06-10", "--hours", "12-12", "--sensors", sensors, "--paths", "2000",
                  "--output", "out/room.pvd"], tmp_path)
    assert result.returncode == 0, result.stderr
    # Every one of those noons is sunny in the file (DNI 459 to 897 W/m^2).
    last = read_sensor_series(tmp_path)[-1][1]
    assert last.GetPointData().GetArray("DirectSunHours").GetValue(0) == 10


@pytest.mark.parametrize("args, words", [
    (["--weather", WEATHER, "--sun-path", "48.85,2.35,2024-06-21,06:00,07:00,60"],
     "without --sun-directions and --sun-path"),
    (["--weather", WEATHER, "--time-zone", "1"], "without --time-zone"),
    (["--weather", WEATHER, "--sun-irradiance", "500"], "--sun-irradiance"),
    (["--dates", "06-01,06-02"], "choose the hours of --weather"),
    (["--night"], "choose the hours of --weather"),
    (["--weather", WEATHER, "--dates", "02-30,03-01"], "days that exist"),
    (["--weather", WEATHER, "--dates", "06-01"], "MM-DD,MM-DD"),
    (["--weather", WEATHER, "--hours", "17-8"], "the first hour first"),
    (["--weather", WEATHER, "--hours", "8-24"], "0 to 23"),
    (["--weather", WEATHER, "--night=yes"], "--night takes no value"),
    (["--weather", "paris.csv"], "give an EnergyPlus weather file (.epw)"),
])
def test_bad_weather_options_are_refused_by_name(tmp_path, args, words):
    result = run(["--scene", write_ground(tmp_path)] + args + ["--output", "o/s.pvd"], tmp_path)
    assert result.returncode == 2, result.stderr
    assert words in result.stderr
    assert not (tmp_path / "o").exists()


def test_bad_weather_files_are_refused_with_their_line(tmp_path):
    ground = write_ground(tmp_path)
    lines = open(WEATHER).read().split("\n")
    lines[1000] = lines[1000].replace(",*9,", ",*9,", 1)
    fields = lines[1000].split(",")
    fields[14] = "-5"
    lines[1000] = ",".join(fields)
    (tmp_path / "bad.epw").write_text("\n".join(lines))
    result = run(["--scene", ground, "--weather", "bad.epw", "--output", "o/s.pvd"], tmp_path)
    assert result.returncode == 1, result.stderr
    assert "the weather file bad.epw, line 1001: the direct normal irradiance is -5" in result.stderr
    assert not (tmp_path / "o").exists()

    result = run(["--scene", ground, "--weather", "missing.epw", "--output", "o/s.pvd"], tmp_path)
    assert result.returncode == 1
    assert "cannot read the weather file missing.epw" in result.stderr

    # Hours that are all night: nothing to solve, and the message says how to widen them.
    result = run(["--scene", ground, "--weather", WEATHER, "--dates", "12-21,12-21", "--hours",
                  "0-5", "--output", "o/s.pvd"], tmp_path)
    assert result.returncode == 1
    assert "only night" in result.stderr and "include the night" in result.stderr

"""The plugin's Sun Path source reads a weather file as ParaView users meet it, in pvbatch:
its WeatherFile, FirstDate, LastDate, Hours and IncludeNight properties (documented, with
the VTK source's defaults), the hours it makes (the time steps of Moving Light Radiosity are
the hours of the year), and the filter lit by that sun and a Perez sky; and the panel's ranges
of every numeric property of Sun Path: each bound of a range domain (each element's, with the
others at their defaults) updates without an error, a value just outside fails the update.

    pvbatch --force-offscreen-rendering pvbatch_weather.py --plugin MovingLightRadiosity.so

MLR_DATA_DIR names Data/ (paris_synthetic.epw)."""
import os
import sys

import plugin_test_support as support

args = support.parse_arguments(__doc__.splitlines()[0])

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403 (LoadPlugin adds the sources here)

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.Weather")
check = checks.check

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from vtk_messages import recorded  # noqa: E402

weather = os.path.join(os.environ["MLR_DATA_DIR"], "paris_synthetic.epw")
sun = SunPath()  # noqa: F405
proxy = sun.SMProxy
for name, default in (("WeatherFile", [""]), ("FirstDate", [1, 1]), ("LastDate", [12, 31]),
                      ("Hours", [0, 23]), ("IncludeNight", [0])):
    prop = proxy.GetProperty(name)
    if not check(prop is not None, f"Sun Path has no property {name}"):
        continue
    documentation = prop.GetDocumentation()
    check(documentation is not None and "Default" in documentation.GetDescription(),
          f"{name} has no documentation naming its default")
    value = sun.GetPropertyValue(name)
    value = list(value) if isinstance(value, (list, tuple)) or hasattr(value, "__len__") and \
        not isinstance(value, str) else [value]
    check(value == default, f"{name} is {value} by default, expected {default}")

# The panel shows the weather file's own properties with a file, the day's without.
WEATHER_ONLY = {"FirstDate", "LastDate", "Hours", "IncludeNight"}
DAY_ONLY = {"Latitude", "Longitude", "Year", "Month", "Day", "StartTime", "EndTime",
            "StepMinutes", "TimeZone"}
file_property = proxy.GetProperty("WeatherFile")
for typed in ("", weather):
    file_property.SetUncheckedElement(0, typed)
    for name in WEATHER_ONLY | DAY_ONLY | {"WeatherFile", "North", "Up"}:
        expected = name not in (DAY_ONLY if typed else WEATHER_ONLY)
        actual = support.shown(proxy, name)
        check(actual == expected, f"Sun Path's {name} is {'shown' if actual else 'hidden'} "
              f"with WeatherFile {typed!r}: expected the opposite")
file_property.ClearUncheckedElements()

sun.WeatherFile = weather
sun.FirstDate = [6, 21]
sun.LastDate = [6, 21]
sun.Hours = [9, 11]
sun.UpdatePipeline()
path = servermanager.Fetch(sun)
check(path.GetNumberOfPoints() == 3, f"{path.GetNumberOfPoints()} points for three hours")
for name in ("Time", "DayOfYear", "ClockHour", "DirectNormalIrradiance", "SkyDiffuseHorizontal",
             "GlobalHorizontalIrradiance", "SunElevation", "Power"):
    check(path.GetPointData().GetArray(name) is not None, f"no point array {name}")

ground = Plane()  # noqa: F405
radiosity = MovingLightRadiosity(Scene=ground, Trajectory=sun,  # noqa: F405
                                 LightType="Directional", SkyModel="Perez", NumberOfPaths=5000)
radiosity.UpdatePipelineInformation()
steps = list(radiosity.TimestepValues)
expected = [171 * 24 + h for h in (9, 10, 11)]
check(steps == expected, f"time steps {steps}, expected the hours of the year {expected}")
radiosity.UpdatePipeline(expected[1])
elements = servermanager.Fetch(radiosity)
irradiance = elements.GetCellData().GetArray("Irradiance")
check(irradiance is not None and irradiance.GetRange(0)[1] > 100,
      "no Irradiance from the weather file's sun and sky at June 21 10:00-11:00")

# --- The panel's ranges -------------------------------------------------------------------
# Each bound of a domain updates; just outside, the update fails. The other properties are
# set so that only the one probed decides: a month of 31 days for Day, the whole day for the
# times, one instant for the step (at most 100000 steps), and the weather file with the night
# hours for its own properties.
AROUND = {"Day": {"Month": 1}, "StartTime": {"EndTime": 24}, "EndTime": {"StartTime": 0},
          "StepMinutes": {"StartTime": 12, "EndTime": 12},
          "FirstDate": {"WeatherFile": weather, "IncludeNight": 1},
          "LastDate": {"WeatherFile": weather, "IncludeNight": 1},
          "Hours": {"WeatherFile": weather, "IncludeNight": 1}}
# Numeric properties without a range domain: directions, and Year (-4000 to 9999 in the
# source), which both bounds would turn into a slider over 14,000 years.
NO_RANGE = {"North", "Up", "Year", "IncludeNight"}


def sun_errors(name, value):
    probe = SunPath(**AROUND.get(name, {}))  # noqa: F405
    probe.SetPropertyWithName(name, value)
    errors = recorded(probe.GetClientSideObject(), "ErrorEvent")
    probe.UpdatePipeline()
    Delete(probe)  # noqa: F405
    return errors


pristine_source = SunPath()  # noqa: F405 (the defaults: the Sun Path above has other dates)
pristine = pristine_source.SMProxy
iterator = proxy.NewPropertyIterator()
iterator.Begin()
while not iterator.IsAtEnd():
    name, prop = iterator.GetKey(), iterator.GetProperty()
    iterator.Next()
    if prop.GetInformationOnly() or not (prop.IsA("vtkSMIntVectorProperty") or
                                         prop.IsA("vtkSMDoubleVectorProperty")):
        continue
    domain = prop.FindDomain("vtkSMIntRangeDomain") or prop.FindDomain("vtkSMDoubleRangeDomain")
    if name in NO_RANGE or not check(domain is not None, f"Sun Path's {name} has no range domain"):
        continue
    counts = domain.IsA("vtkSMIntRangeDomain")
    default = [pristine.GetProperty(name).GetElement(i) for i in range(prop.GetNumberOfElements())]
    for i in range(prop.GetNumberOfElements()):
        for bound, exists, get, outward in ((" minimum", domain.GetMinimumExists,
                                             domain.GetMinimum, -1),
                                            (" maximum", domain.GetMaximumExists,
                                             domain.GetMaximum, +1)):
            if not exists(i):
                continue
            value = get(i)
            outside = value + outward if counts else value + outward * (1e-6 + abs(value))
            for probed, taken in ((value, True), (outside, False)):
                given = list(default)
                given[i] = probed
                errors = sun_errors(name, given if len(given) > 1 else given[0])
                check(bool(errors) != taken,
                      f"Sun Path's {name} {given} ({'the' if taken else 'outside the'} domain's"
                      f"{bound}) {'fails' if errors else 'updates'}: {errors}")
Delete(pristine_source)  # noqa: F405

checks.finish()

"""Colouring the Elements by Illuminance, checked in pvbatch with ParaView sources only:

- the first Apply still shows the point array Color with Map Scalars off;
- coloured by the point array Illuminance, Map Scalars turns on, the lookup table uses log
  scale and the preset Illuminance (lux, log) of Plugin/Display/IlluminancePresets.json
  (registered by the plugin, its colours in order, its points a constant ratio apart as a log
  rescale leaves them), spans the data's range in lux (a minimum of 0 raised to 1e-4 of the
  maximum, at most 1 lx, as ParaView does) and the scalar bar is titled in lux;
- coloured by Color again, Map Scalars turns off;
- a lookup table for another array (Radiosity) keeps ParaView's defaults;
- a day of sun on the box (night frames 0 lx everywhere, lit ones 0 lx on the faces turned
  away): Color By, Rescale to Data Range at each time, Rescale over All Timesteps and the
  lookup tables' rescale of the GUI's Apply print no "Ranges not valid for log-space"; the lookup
  table stays on a log scale from min(1e-4 of the maximum, 1 lx) to the maximum, a night frame
  leaves it as it was, and the colour array's own range still starts at 0.

    pvbatch --force-offscreen-rendering pvbatch_illuminance.py --plugin MovingLightRadiosity.so"""
import json
import os

import numpy

import plugin_test_support as support

args = support.parse_arguments(__doc__.splitlines()[0])

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403
from paraview.modules.vtkRemotingViews import (vtkSMTransferFunctionManager,
                                               vtkSMTransferFunctionPresets)
from vtkmodules.util.numpy_support import vtk_to_numpy

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.Illuminance")
check = checks.check

PRESET = "Illuminance (lux, log)"
with open(os.path.join(os.path.dirname(__file__), "..", "..", "Plugin", "Display",
                       "IlluminancePresets.json")) as stream:
    preset = next(p for p in json.load(stream) if p["Name"] == PRESET)
preset_rgb = numpy.array(preset["RGBPoints"]).reshape(-1, 4)[:, 1:]

radiosity, sources = support.box_pipeline()
radiosity.UpdatePipeline(4.0)
view = CreateRenderView()
display = Show(radiosity, view)
check(list(display.ColorArrayName) == ["POINTS", "Color"] and display.MapScalars == 0,
      f"the first Apply shows {list(display.ColorArrayName)} with Map Scalars "
      f"{display.MapScalars}, expected point Color with Map Scalars off")
check(vtkSMTransferFunctionPresets.GetInstance().HasPreset(PRESET),
      f"the plugin did not register the preset {PRESET!r}")

ColorBy(display, ("POINTS", "Illuminance"))
display.RescaleTransferFunctionToDataRange(False, True)
display.SetScalarBarVisibility(view, True)
check(display.MapScalars == 1, "colouring by Illuminance left Map Scalars off: the lux values "
      "would be read as colours")
lut = GetColorTransferFunction("Illuminance")
check(lut.UseLogScale == 1, "the Illuminance lookup table is linear")
points = numpy.array(lut.RGBPoints).reshape(-1, 4)
if check(points.shape == (len(preset_rgb), 4),
         f"the lookup table has {len(points)} points, the preset {len(preset_rgb)}"):
    check(numpy.allclose(points[:, 1:], preset_rgb),
          f"the lookup table's colours {points[:, 1:].tolist()} are not the preset's")
    ratios = points[1:, 0] / points[:-1, 0]
    check(numpy.all(points[:, 0] > 0) and numpy.allclose(ratios, ratios[0], rtol=1e-6),
          f"the lookup table's points {points[:, 0].tolist()} are not evenly spaced in log")
    data = servermanager.Fetch(radiosity)
    lux = vtk_to_numpy(data.GetPointData().GetArray("Illuminance"))
    low = lux.min() if lux.min() > 0 else min(1e-4 * lux.max(), 1.0)  # ParaView's log range
    check(lux.max() > 0, "no element is lit")
    check(numpy.isclose(points[-1, 0], lux.max(), rtol=1e-6) and
          numpy.isclose(points[0, 0], low, rtol=1e-6),
          f"the lookup table spans {points[0, 0]:g} - {points[-1, 0]:g} lx, the data "
          f"{lux.min():g} - {lux.max():g} lx")
bar = GetScalarBar(lut, view)
check("(lx)" in bar.Title, f"the scalar bar is titled {bar.Title!r}, not in lux")

ColorBy(display, ("POINTS", "Color"))
check(display.MapScalars == 0, "back on Color, Map Scalars stayed on: the colours would go "
      "through the lux colour map")

other = GetColorTransferFunction("Radiosity")
check(other.UseLogScale == 0, "the Radiosity lookup table is on a log scale too")

# --- 0 lx on a log scale ------------------------------------------------------------------
# ParaView 5.11 raises a log-scale range that reaches 0 itself, with a warning at each rescale
# (vtkSMTransferFunctionProxy). The representations of the outputs with Illuminance give the
# lookup table ParaView's range without it.
for name in ("MovingLightRadiosityElementsRepresentation",
             "MovingLightRadiositySensorsRepresentation"):
    representation = servermanager.ProxyManager().SMProxyManager.NewProxy("representations", name)
    kind = representation.GetClassName() if representation else None
    check(kind == "vtkSMMovingLightRadiosityRepresentationProxy",
          f"{name} is a {kind}: its log-scale colour maps would be rescaled to a range from 0")

Delete(radiosity)
for source in sources.values():
    Delete(source)
box = Box()
sun = SunPath(StartTime=0, EndTime=24, StepMinutes=180)  # Paris, June 21: night at 0, 3, 21, 24
day = MovingLightRadiosity(Scene=box, Trajectory=sun, LightType="Directional",
                           NumberOfPaths=support.TEST_PATHS)
day.UpdatePipeline(0.0)
times = list(day.TimestepValues)
lux_range = {}
for t in times:
    day.UpdatePipeline(t)
    values = vtk_to_numpy(servermanager.Fetch(day).GetPointData().GetArray("Illuminance"))
    lux_range[t] = (float(values.min()), float(values.max()))
lit = [t for t in times if lux_range[t][1] > 0]


def lut_range():
    return (lut.RGBPoints[0], lut.RGBPoints[-4])


def expected(t):
    """ParaView's log range for data from 0 lx (vtkSMCoreUtilities::AdjustRangeForLog)."""
    return (min(1e-4 * lux_range[t][1], 1.0), lux_range[t][1])


if check(lit and len(lit) < len(times) and all(lux_range[t][0] == 0 for t in times),
         f"the day's Illuminance ranges {lux_range}: expected 0 lx somewhere in every frame "
         "and some frames dark"):
    noon = max(lit, key=lambda t: lux_range[t][1])
    view = CreateRenderView()
    view.ViewTime = noon
    day.UpdatePipeline(noon)
    display = Show(day, view)
    with support.PrintedMessages() as printed:
        ColorBy(display, ("POINTS", "Illuminance"))
        lut = GetColorTransferFunction("Illuminance")
        check(lut.UseLogScale == 1, "the Illuminance lookup table is linear")
        check(numpy.allclose(lut_range(), expected(noon), rtol=1e-6),
              f"coloured at {noon} h, the lookup table spans {lut_range()} lx, expected "
              f"{expected(noon)}")
        info = display.GetArrayInformationForColorArray()
        check(info.GetComponentRange(-1)[0] == 0 and info.GetComponentRange(0)[0] == 0,
              f"the colour array's range {info.GetComponentRange(-1)} no longer starts at 0 lx")
        for t in times:
            before = lut_range()
            view.ViewTime = t
            day.UpdatePipeline(t)
            display.RescaleTransferFunctionToDataRange(False, True)
            if t in lit:
                check(numpy.allclose(lut_range(), expected(t), rtol=1e-6),
                      f"rescaled at {t} h, the lookup table spans {lut_range()} lx, expected "
                      f"{expected(t)}")
            else:
                check(lut_range() == before, f"rescaled at night ({t} h, 0 lx everywhere), the "
                      f"lookup table went from {before} to {lut_range()} lx")
        display.RescaleTransferFunctionToDataRangeOverTime()
        # The GUI's Apply: every lookup table grows to its representations' data.
        view.ViewTime = noon
        day.UpdatePipeline(noon)
        vtkSMTransferFunctionManager().ResetAllTransferFunctionRangesUsingCurrentData(
            servermanager.ProxyManager().SMProxyManager, False)
        check(lut.UseLogScale == 1 and lut_range()[0] > 0,
              f"after the rescales the lookup table spans {lut_range()} lx, log scale "
              f"{lut.UseLogScale}")
    check("log-space" not in printed.text,
          "rescaling the log-scale Illuminance of frames with 0 lx printed:\n" + printed.text)

checks.finish()

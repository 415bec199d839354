"""Colouring the Elements by Illuminance, checked in pvbatch with ParaView sources only:

- the first Apply still shows the point array Color with Map Scalars off;
- coloured by the point array Illuminance, Map Scalars turns on, the lookup table uses log
  scale and the preset Illuminance (lux, log) of Plugin/Display/IlluminancePresets.json
  (registered by the plugin, its colours in order, its points a constant ratio apart as a log
  rescale leaves them), spans the data's range in lux (a minimum of 0 raised to 1e-4 of the
  maximum, at most 1 lx, as ParaView does) and the scalar bar is titled in lux;
- coloured by Color again, Map Scalars turns off;
- a lookup table for another array (Radiosity) keeps ParaView's defaults.

    pvbatch --force-offscreen-rendering pvbatch_illuminance.py --plugin MovingLightRadiosity.so"""
import json
import os

import numpy

import plugin_test_support as support

args = support.parse_arguments(__doc__.splitlines()[0])

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403
from paraview.modules.vtkRemotingViews import vtkSMTransferFunctionPresets
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

checks.finish()

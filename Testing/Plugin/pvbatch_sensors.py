"""The Sensors input and output in pvbatch with ParaView sources only: a Plane of 9 x 9
points 0.8 above a ground Plane (its point array Normals faces up) as the Sensors of a sun
with a uniform sky, the Sensors output port (81 vertices with Irradiance, Illuminance and the
daylight metrics), and the work plane coloured by DaylightAutonomy as in the GUI.

    pvbatch --force-offscreen-rendering pvbatch_sensors.py --plugin MovingLightRadiosity.so"""
import numpy

import plugin_test_support as support

args = support.parse_arguments(__doc__.splitlines()[0])

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.Sensors")
check = checks.check

ground = Plane(Origin=[-2, -2, 0], Point1=[2, -2, 0], Point2=[-2, 2, 0], XResolution=4,
               YResolution=4)
plane = Plane(Origin=[-1, -1, 0.8], Point1=[1, -1, 0.8], Point2=[-1, 1, 0.8], XResolution=8,
              YResolution=8)
# Towards the sun: three directions, the last below the horizon.
suns = Line(Point1=[1, 0, 1], Point2=[1, 0, -0.2], Resolution=2)
radiosity = MovingLightRadiosity(Scene=ground, Trajectory=suns, Sensors=plane)
radiosity.LightType = "Directional"
radiosity.SunIrradiance = 500
radiosity.SkyModel = "Uniform"
radiosity.SkyDiffuseHorizontal = 20
radiosity.NumberOfPaths = 20000
radiosity.PatchSize = 1.0
radiosity.DaylightAutonomyThreshold = 5000

check(radiosity.GetProperty("Sensors") is not None, "no Sensors input property")
radiosity.UpdatePipeline(0.0)
data = servermanager.Fetch(radiosity, None, None, 3)
check(data.GetNumberOfPoints() == 81 and data.GetNumberOfVerts() == 81,
      f"the Sensors output has {data.GetNumberOfPoints()} points and {data.GetNumberOfVerts()} "
      "vertices, expected 81 of each")
for name in ("Irradiance", "Illuminance", "DaylightAutonomy", "UDILow", "UDIUseful", "UDIHigh",
             "DirectSunHours", "Normals"):
    check(data.GetPointData().GetArray(name) is not None, f"the Sensors output has no {name}")
if data.GetPointData().GetArray("DaylightAutonomy") is not None:
    da = vtk_to_numpy(data.GetPointData().GetArray("DaylightAutonomy"))
    lux = vtk_to_numpy(data.GetPointData().GetArray("Illuminance"))
    # Every sensor sees the whole sky and the sun: above 5000 lx in the two frames of sun
    # only (the third is the sky's 20 W/m^2, about 2500 lx).
    check(numpy.allclose(da, 2 / 3), f"DaylightAutonomy {sorted(set(da.tolist()))}, expected 2/3")
    check(numpy.all(lux > 5000), f"frame 0 Illuminance {lux.min()} - {lux.max()} lx")
    hours = vtk_to_numpy(data.GetPointData().GetArray("DirectSunHours"))
    check(numpy.allclose(hours, 2), f"DirectSunHours {sorted(set(hours.tolist()))}, expected 2")

view = CreateRenderView()
display = Show(OutputPort(radiosity, 3), view)
ColorBy(display, ("POINTS", "DaylightAutonomy"))
check(list(display.ColorArrayName) == ["POINTS", "DaylightAutonomy"],
      f"the work plane is coloured by {list(display.ColorArrayName)}")

checks.finish()

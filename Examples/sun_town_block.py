"""A day of sun on a small town block, in ParaView: radiosity with inter-reflections for every
sun position, written as a .pvd/.vtu series with one picture per time step.

    xvfb-run -a pvpython Examples/sun_town_block.py [--plugin PATH] [--output DIR] [--paths N]
        [--weather [FILE.epw]]

The block is a ground square with five box buildings of different heights and colours. Sources >
Sun Path gives the directions towards the sun for Paris on 21 June 2024 from 05:00 to 22:00
summer time (UTC+2) every 30 minutes; Moving Light Radiosity with Light Type Directional
solves every time step at once (paths reused over the sun's directions). Night steps are kept,
dark, so that the series' times are the clock hours. With --weather (default file
Data/paris_synthetic.epw, an EnergyPlus weather file) Sun Path reads the hours 06:00 to 20:00
of 21 June from the file instead, each hour's sun at its middle with the file's direct normal
irradiance, and a Perez sky of its diffuse horizontal irradiance lights the block too; the
series' times are then the hours of the year (4110 is 06:00-07:00 on 21 June). Writes

  DIR/town.pvd + DIR/town/*.vtu    the Elements of every time step (Radiosity in W/m^2,
                                   DirectRadiosity, IndirectRadiosity, field data SunAzimuth and
                                   SunElevation in degrees);
  DIR/png/frame_0000.png ...       one picture per time step, in the filter's display colours.

DIR defaults to output/sun.
"""
import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import example_support  # noqa: E402

parser = argparse.ArgumentParser(description="A day of sun on a town block, with the ParaView plugin.")
parser.add_argument("--plugin", help="MovingLightRadiosity.so to load (default: the build tree's)")
parser.add_argument("--output", default=os.path.join("output", "sun"),
                    help="folder for town.pvd, town/ and png/ (default: %(default)s)")
parser.add_argument("--paths", type=int, default=600000,
                    help="effective paths per time step (default: %(default)s)")
parser.add_argument("--step", type=float, default=30, help="minutes between time steps (default: 30)")
parser.add_argument("--size", type=int, default=640, help="picture size in pixels (default: 640)")
parser.add_argument("--weather", nargs="?", metavar="FILE.epw",
                    const=os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "Data",
                                       "paris_synthetic.epw"),
                    help="the hours of 21 June from an EnergyPlus weather file, with a Perez sky "
                         "(default file: Data/paris_synthetic.epw)")
args = parser.parse_args()
if args.paths < 1 or args.size < 16 or not args.step > 0:
    parser.error("--paths must be >= 1, --size >= 16 and --step > 0")
x_connection = example_support.require_display(parser, "Examples/sun_town_block.py")

import paraview.simple as pv  # noqa: E402

example_support.load_plugin(pv, parser, args.plugin)

# --- The town block: boxes on a ground square (metres; x east, y north, z up) --------------
BUILDINGS = [  # centre x, centre y, width, depth, height, reflectance
    (-14, -10, 12, 10, 18, (0.55, 0.50, 0.45)),
    (6, -12, 14, 8, 9, (0.70, 0.68, 0.62)),
    (-12, 12, 10, 12, 12, (0.45, 0.35, 0.30)),
    (10, 10, 8, 8, 24, (0.60, 0.62, 0.66)),
    (0, 0, 6, 6, 6, (0.75, 0.55, 0.40)),
]
parts = []
ground = pv.Plane(registrationName="Ground", Origin=[-40, -40, 0], Point1=[40, -40, 0],
                  Point2=[-40, 40, 0])
parts.append((ground, (0.25, 0.25, 0.25)))
for i, (x, y, w, d, h, rho) in enumerate(BUILDINGS):
    box = pv.Box(registrationName=f"Building{i}", XLength=w, YLength=d, ZLength=h,
                 Center=[x, y, h / 2])
    parts.append((box, rho))
coloured = []
for source, rho in parts:
    # A constant cell array Reflectance per part (Calculator on cells, as a user would).
    surface = pv.Triangulate(Input=source)
    coloured.append(pv.Calculator(Input=surface, AttributeType="Cell Data", ResultArrayName="Reflectance",
                                  Function=f"{rho[0]}*iHat+{rho[1]}*jHat+{rho[2]}*kHat"))
town = pv.ExtractSurface(registrationName="Town", Input=pv.AppendDatasets(Input=coloured))

if args.weather:
    sun = pv.SunPath(registrationName="SunPath", WeatherFile=os.path.abspath(args.weather),
                     FirstDate=[6, 21], LastDate=[6, 21], Hours=[6, 19])
    sky = {"SkyModel": "Perez"}
else:
    sun = pv.SunPath(registrationName="SunPath", Latitude=48.85, Longitude=2.35, Year=2024,
                     Month=6, Day=21, StartTime=5, EndTime=22, StepMinutes=args.step, TimeZone=2)
    sky = {}
radiosity = pv.MovingLightRadiosity(registrationName="MovingLightRadiosity", Scene=town,
                                    Trajectory=sun, LightType="Directional", SunIrradiance=1000,
                                    NumberOfPaths=args.paths, **sky)

started = time.time()
radiosity.UpdatePipelineInformation()
first = list(radiosity.TimestepValues)[:1] or [0.0]
radiosity.UpdatePipeline(time=first[0])
if radiosity.GetDataInformation().GetNumberOfCells() == 0:
    sys.exit("the filter produced nothing: see the error above")
times = list(radiosity.TimestepValues)
print(f"solved {len(times)} sun positions ({times[0]:g} h to {times[-1]:g} h), "
      f"{radiosity.GetDataInformation().GetNumberOfCells()} elements, in {time.time() - started:.1f} s")

os.makedirs(args.output, exist_ok=True)
series = os.path.join(args.output, "town.pvd")
pv.SaveData(series, proxy=pv.MergeBlocks(Input=radiosity), WriteTimeSteps=1)
print(f"wrote {series}")

view = example_support.picture_view(pv, args.size, [0.55, 0.7, 0.9])
pv.Show(radiosity, view)
view.CameraPosition = [70, -90, 75]
view.CameraFocalPoint = [0, 0, 4]
view.CameraViewUp = [0, 0, 1]
view.CameraViewAngle = 30
pictures = os.path.join(args.output, "png")
example_support.save_pictures(pv, view, times, pictures, args.size)
print(f"wrote {len(times)} pictures in {pictures}")

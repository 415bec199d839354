"""A spotlight that pans across the Cornell box, in ParaView: the lamp hangs below the ceiling
and turns 90 degrees over the animation, from lighting the green wall to lighting the red one.
It is a real spot of 800 lm: uniform within 20 degrees of its axis, fading to dark over 10
more (Spot Half Angle, Spot Soft Edge, Light Flux Lumens).

    xvfb-run -a pvpython Examples/panning_spotlight.py [--plugin PATH] [--output DIR] [--paths N]

The Trajectory is a polyline of points (the lamp's centroid, here fixed) with a point array
Normal: the lamp's emission direction in each time step. Moving Light Radiosity turns the lamp
about its centroid by the smallest rotation from its own normal to that direction, and reuses
every path over all the directions. (An Orientation array, quaternions w, x, y, z, would give
the full rotation instead; Aim At Point makes every lamp face one point.) Writes
DIR/spotlight.pvd with DIR/spotlight/*.vtu and DIR/png/frame_0000.png ... (default
output/spotlight); the lamp is shown in yellow where it points. DIR/png/illuminance.png shows
the middle step's Illuminance in lux on the plugin's log false-colour legend.
"""
import argparse
import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import example_support  # noqa: E402

parser = argparse.ArgumentParser(description="A panning spotlight in the Cornell box, with the ParaView plugin.")
parser.add_argument("--plugin", help="MovingLightRadiosity.so to load (default: the build tree's)")
parser.add_argument("--output", default=os.path.join("output", "spotlight"),
                    help="folder for spotlight.pvd, spotlight/ and png/ (default: %(default)s)")
parser.add_argument("--paths", type=int, default=600000, help="effective paths per step (default: %(default)s)")
parser.add_argument("--steps", type=int, default=30, help="time steps of the pan (default: %(default)s)")
parser.add_argument("--size", type=int, default=512, help="picture size in pixels (default: %(default)s)")
args = parser.parse_args()
if args.paths < args.steps or args.steps < 2 or args.size < 16:
    parser.error("--steps must be >= 2, --paths >= --steps and --size >= 16")
x_connection = example_support.require_display(parser, "Examples/panning_spotlight.py")

import paraview.simple as pv  # noqa: E402
from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkPoints  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter  # noqa: E402

example_support.load_plugin(pv, parser, args.plugin)

# --- The pan: the lamp below the ceiling's centre, its normal sweeping 90 degrees in x ------
# (The Cornell box of Data/: x from the green wall (0) to the red one (0.556), y up, ceiling at
# 0.5488.) The normal tilts from 45 degrees towards the green wall to 45 towards the red one.
centre = (0.278, 0.45, 0.28)
points, normals, line = vtkPoints(), vtkDoubleArray(), vtkCellArray()
normals.SetName("Normal")
normals.SetNumberOfComponents(3)
line.InsertNextCell(args.steps)
for i in range(args.steps):
    angle = math.radians(-45 + 90 * i / (args.steps - 1))
    line.InsertCellPoint(points.InsertNextPoint(*centre))
    normals.InsertNextTuple3(math.sin(angle), -math.cos(angle), 0.0)
trajectory_data = vtkPolyData()
trajectory_data.SetPoints(points)
trajectory_data.SetLines(line)
trajectory_data.GetPointData().AddArray(normals)
trajectory_file = os.path.join(tempfile.mkdtemp(prefix="spotlight-"), "pan.vtp")
writer = vtkXMLPolyDataWriter()
writer.SetInputData(trajectory_data)
writer.SetFileName(trajectory_file)
writer.Write()

data = os.path.join(example_support.ROOT, "Data")
scene = pv.XMLPolyDataReader(registrationName="cornell_box.vtp", FileName=[os.path.join(data, "cornell_box.vtp")])
lamp = pv.Plane(registrationName="Lamp", Origin=[0.248, 0.5478, 0.25], Point1=[0.248, 0.5478, 0.31],
                Point2=[0.308, 0.5478, 0.25])  # 6 cm square, facing down (-y)
trajectory = pv.XMLPolyDataReader(registrationName="pan.vtp", FileName=[trajectory_file])
radiosity = pv.MovingLightRadiosity(registrationName="MovingLightRadiosity", Scene=scene, Light=lamp,
                                    Trajectory=trajectory, LightPower=[1, 1, 1],
                                    LightFluxLumens=800, SpotHalfAngle=20, SpotSoftEdge=10,
                                    NumberOfPaths=args.paths)
radiosity.UpdatePipeline(time=0.0)
if radiosity.GetDataInformation().GetNumberOfCells() == 0:
    sys.exit("the filter produced nothing: see the error above")
times = list(radiosity.TimestepValues)
print(f"solved {len(times)} directions, {radiosity.GetDataInformation().GetNumberOfCells()} elements")

os.makedirs(args.output, exist_ok=True)
series = os.path.join(args.output, "spotlight.pvd")
pv.SaveData(series, proxy=pv.MergeBlocks(Input=radiosity), WriteTimeSteps=1)
print(f"wrote {series}")

view = example_support.picture_view(pv, args.size, [0.0, 0.0, 0.0])
elements = pv.Show(radiosity, view)
pv.Show(pv.OutputPort(radiosity, 2), view)
view.CameraFocalPoint = [0.278, 0.274, 0.28]
view.CameraPosition = [0.278, 0.274, -0.8]
view.CameraViewUp = [0.0, 1.0, 0.0]
view.CameraViewAngle = 39.3
pictures = os.path.join(args.output, "png")
example_support.save_pictures(pv, view, times, pictures, args.size)
print(f"wrote {len(times)} pictures in {pictures}")

# The middle step in lux: colouring by Illuminance gives the plugin's log legend.
middle = times[len(times) // 2]
pv.GetAnimationScene().AnimationTime = middle
pv.ColorBy(elements, ("POINTS", "Illuminance"))
elements.RescaleTransferFunctionToDataRange(False, True)
elements.SetScalarBarVisibility(view, True)
legend = pv.GetScalarBar(pv.GetColorTransferFunction("Illuminance"), view)
legend.WindowLocation = "Upper Right Corner"
legend.ScalarBarLength = 0.8
legend.RangeLabelFormat = "%.3g"
pv.SaveScreenshot(os.path.join(pictures, "illuminance.png"), view, ImageResolution=[args.size, args.size])
print(f"wrote {os.path.join(pictures, 'illuminance.png')}")

"""What the first Apply shows, checked in pvbatch with ParaView sources only:

- every output port shown as the Apply button shows it (ShowInPreferredView): the Elements
  coloured by the point array Color with Map Scalars off and unlit (Ambient 1, Diffuse 0),
  the Patches not shown, the Light shown in a solid colour distinct from the scene, its
  vertices (a point light) as spheres of several pixels;
- the Elements' point data holds Radiosity and Color (and the cells keep Radiosity);
- the Light port at frames 0, 3 and the last: its area centroid is the trajectory's point
  of that time, its Power adds up to Light Power;
- Exposure +1 doubles the value before the tone map on the floor (a flat region), without a
  new solve;
- Path Start and Path End sit in a property group shown by ParaView's interactive line
  widget and start from the scene's bounds; ParaView's line widget proxy, linked to them as
  the Properties panel links it, moves their end points, and after Apply the filter solves
  again along the new path. The mouse drag itself is not simulated: it ends in the widget's
  end-point properties, which the test sets.

    pvbatch --force-offscreen-rendering pvbatch_display.py --plugin MovingLightRadiosity.so"""
import numpy

import plugin_test_support as support

args = support.parse_arguments(__doc__.splitlines()[0])

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403
from paraview.modules.vtkRemotingViews import vtkSMParaViewPipelineControllerWithRendering
from vtkmodules.util.numpy_support import vtk_to_numpy

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.Display")
check = checks.check

LAST = support.POSITIONS - 1
radiosity, sources = support.box_pipeline()
proxy = radiosity.SMProxy

# --- Apply ----------------------------------------------------------------------------------
radiosity.UpdatePipeline()
view = CreateRenderView()
controller = vtkSMParaViewPipelineControllerWithRendering()
shown = [controller.ShowInPreferredView(proxy, port, view.SMProxy) for port in (0, 1, 2)]
check(shown[0] is not None, "Apply does not show the Elements")
check(shown[1] is None, "Apply shows the Patches on top of the Elements")
check(shown[2] is not None, "Apply does not show the Light")
check(proxy.GetOutputPortName(2) == "Light", f"output port 2 is {proxy.GetOutputPortName(2)!r}")

elements_display = GetDisplayProperties(radiosity, view)
check(list(elements_display.ColorArrayName) == ["POINTS", "Color"],
      f"the Elements are coloured by {list(elements_display.ColorArrayName)}, expected point Color")
check(elements_display.MapScalars == 0, "Map Scalars is on: Color would go through a colour map")
check(elements_display.Representation == "Surface",
      f"the Elements are shown as {elements_display.Representation!r}")
check((elements_display.Ambient, elements_display.Diffuse) == (1.0, 0.0),
      f"the Elements are lit by the view (Ambient {elements_display.Ambient}, Diffuse "
      f"{elements_display.Diffuse}): the colours already are the lighting")
light_display = GetDisplayProperties(OutputPort(radiosity, 2), view)
check(light_display.ColorArrayName[1] == "",
      f"the Light is coloured by {list(light_display.ColorArrayName)}, expected a solid colour")
yellow = list(light_display.DiffuseColor)
check(yellow[0] > 0.8 and yellow[1] > 0.6 and yellow[2] < 0.5,
      f"the Light's colour {yellow} is not the documented yellow")
# A point light is one vertex: drawn as a sphere of some pixels, not a dot of 1 or 2
# (pvbatch_screenshots.py counts them).
check(light_display.RenderPointsAsSpheres == 1 and light_display.PointSize >= 8,
      f"the Light's vertices are drawn as {'spheres' if light_display.RenderPointsAsSpheres else 'dots'}"
      f" {light_display.PointSize} pixels across, expected spheres of 8 pixels or more")
# The Sensors likewise: a work plane of 2-pixel dots was hard to see (QA).
controller.ShowInPreferredView(proxy, 3, view.SMProxy)
sensors_display = GetDisplayProperties(OutputPort(radiosity, 3), view)
check(sensors_display.RenderPointsAsSpheres == 1 and sensors_display.PointSize == 8,
      f"the Sensors are drawn as {'spheres' if sensors_display.RenderPointsAsSpheres else 'dots'}"
      f" {sensors_display.PointSize} pixels across, expected spheres of 8 pixels")


def fetch(time, port=0):
    radiosity.UpdatePipeline(time=time)
    return servermanager.Fetch(radiosity, idx=port)


def field(data, name):
    array = data.GetFieldData().GetArray(name)
    if array is None:
        return None
    return array.GetTuple(0) if array.GetNumberOfComponents() > 1 else array.GetValue(0)


# --- Arrays ---------------------------------------------------------------------------------
data = fetch(0.0)
for name in ("Radiosity", "Color"):
    array = data.GetPointData().GetArray(name)
    check(array is not None and array.GetNumberOfComponents() == 3,
          f"point data has no 3-component {name}")
color = data.GetPointData().GetArray("Color")
check(color is not None and color.GetDataTypeAsString() == "unsigned char",
      f"point Color is {color.GetDataTypeAsString() if color else None}, expected unsigned char")
for name in ("Radiosity", "DirectRadiosity", "IndirectRadiosity", "Color", "PatchId"):
    check(data.GetCellData().GetArray(name) is not None, f"cell data lost {name}")


# --- The light ------------------------------------------------------------------------------
def polygon_centroid(light):
    points = vtk_to_numpy(light.GetPoints().GetData())
    offsets = vtk_to_numpy(light.GetPolys().GetOffsetsArray())
    ids = vtk_to_numpy(light.GetPolys().GetConnectivityArray())
    weighted, total = numpy.zeros(3), 0.0
    for begin, end in zip(offsets[:-1], offsets[1:]):
        polygon = points[ids[begin:end]]
        for k in range(1, len(polygon) - 1):
            a, b, c = polygon[0], polygon[k], polygon[k + 1]
            area = 0.5 * numpy.linalg.norm(numpy.cross(b - a, c - a))
            weighted += area * (a + b + c) / 3
            total += area
    return weighted / total


for frame in (0, 3, LAST):
    light = fetch(float(frame), port=2)
    if not check(light.GetNumberOfCells() > 0, f"frame {frame}: the Light output is empty"):
        continue
    centroid = polygon_centroid(light)
    expected = numpy.array(support.light_position(frame))
    check(numpy.allclose(centroid, expected, atol=1e-9),
          f"frame {frame}: the Light's centroid is {centroid}, the trajectory's point {expected}")
    power = light.GetCellData().GetArray("Power")
    check(power is not None and numpy.allclose(vtk_to_numpy(power).sum(axis=0), radiosity.LightPower),
          f"frame {frame}: the Light's Power does not add up to Light Power {list(radiosity.LightPower)}")
    check(field(light, "FrameIndex") == frame, f"frame {frame}: the Light shows frame "
          f"{field(light, 'FrameIndex')}")


# --- Exposure -------------------------------------------------------------------------------
def inverse_tone_map(byte):
    """The exposed linear value an 8-bit colour shows, through sRGB and ACES (Narkowicz)."""
    c = byte / 255.0
    linear = numpy.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    # Solve 2.43 y x^2 + 0.59 y x + 0.14 y = 2.51 x^2 + 0.03 x for x.
    a, b, k = 2.43 * linear - 2.51, 0.59 * linear - 0.03, 0.14 * linear
    return (-b - numpy.sqrt(b * b - 4 * a * k)) / (2 * a)


def floor_green(data):
    points = vtk_to_numpy(data.GetPoints().GetData())
    triangles = vtk_to_numpy(data.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    floor = numpy.abs(points[triangles][:, :, 2].mean(axis=1) - support.FLOOR_Z) < 1e-6
    return vtk_to_numpy(data.GetCellData().GetArray("Color"))[floor, 1].astype(float)


before = fetch(4.0)
solves = field(before, "SolveCount")
radiosity.Exposure = 1.0
after = fetch(4.0)
check(field(after, "SolveCount") == solves, "Exposure 1 solved again")
check(numpy.isclose(field(after, "ExposureScale"), 2 * field(before, "ExposureScale")),
      f"Exposure 1 made ExposureScale {field(after, 'ExposureScale')}, expected twice "
      f"{field(before, 'ExposureScale')}")
g0, g1 = floor_green(before), floor_green(after)
usable = (g0 > 40) & (g1 < 230)
if check(usable.sum() > 10, f"only {usable.sum()} floor cells have mid-range colours"):
    ratio = numpy.median(inverse_tone_map(g1[usable]) / inverse_tone_map(g0[usable]))
    check(abs(ratio - 2) < 0.05, f"Exposure +1 multiplied the floor's value by {ratio:.3f}, not 2")
radiosity.Exposure = 0.0

# --- The path widget ------------------------------------------------------------------------
def line_widget_group(source):
    found = None
    for index in range(source.GetNumberOfPropertyGroups()):
        candidate = source.GetPropertyGroup(index)
        if candidate.GetPanelWidget() == "InteractiveLine":
            found = candidate
    return found


group = line_widget_group(proxy)
if check(group is not None, "no property group with panel_widget=\"InteractiveLine\""):
    for function, name in (("Point1WorldPosition", "PathStart"), ("Point2WorldPosition", "PathEnd"),
                           ("Input", "Scene")):
        prop = group.GetProperty(function)
        check(prop is not None and prop is proxy.GetProperty(name),
              f"the line widget's {function} is not the property {name}")

# Defaults from the scene's bounds: a Box of 1 centred on the origin, no Trajectory.
box = Box()
box.UpdatePipeline()
straight = MovingLightRadiosity(Scene=box, Light=sources["light"], NumberOfPaths=support.TEST_PATHS,
                                NumberOfPositions=4)
check(numpy.allclose(straight.PathStart, [-0.5, 0, 0]) and numpy.allclose(straight.PathEnd, [0.5, 0, 0]),
      f"the straight path starts {list(straight.PathStart)} and ends {list(straight.PathEnd)}, "
      "expected the middles of the box's -x and +x faces")
straight.UpdatePipeline(0.0)
first = servermanager.Fetch(straight)

# Drag the ends as the Properties panel's line widget does: ParaView's LineWidgetRepresentation
# linked to the property group (pqInteractivePropertyWidget::setupConnections), its end points
# moved (a drag ends in those properties), then Apply (the unchecked values become the values).
from paraview.modules.vtkRemotingServerManager import vtkSMParaViewPipelineController  # noqa: E402

widget = servermanager.rendering.LineWidgetRepresentation()
vtkSMParaViewPipelineController().InitializeProxy(widget.SMProxy)
straight_group = line_widget_group(straight.SMProxy)
check(widget.SMProxy.LinkProperties(straight.SMProxy, straight_group),
      "the line widget does not link to the path's properties")
check(numpy.allclose(widget.Point1WorldPosition, straight.PathStart) and
      numpy.allclose(widget.Point2WorldPosition, straight.PathEnd),
      f"the line widget shows {list(widget.Point1WorldPosition)} - {list(widget.Point2WorldPosition)}, "
      f"not the path {list(straight.PathStart)} - {list(straight.PathEnd)}")
start, end = [-0.3, -0.2, support.LIGHT_Z], [0.25, 0.3, support.LIGHT_Z]
widget.Point1WorldPosition, widget.Point2WorldPosition = start, end
for name in ("PathStart", "PathEnd"):
    prop = straight.SMProxy.GetProperty(name)
    pending = [prop.GetUncheckedElement(i) for i in range(3)]
    check(numpy.allclose(pending, start if name == "PathStart" else end),
          f"dragging the widget left {name} pending at {pending}")
    prop.SetElements(pending)  # Apply
straight.SMProxy.UpdateVTKObjects()
for time, expected in ((0.0, start), (3.0, end)):
    straight.UpdatePipeline(time)
    moved = servermanager.Fetch(straight)
    check(field(moved, "SolveCount") == field(first, "SolveCount") + 1,
          f"time {time}: moving the path's ends made {field(moved, 'SolveCount')} solves, "
          f"expected {field(first, 'SolveCount') + 1}")
    check(numpy.allclose(field(moved, "LightPosition"), expected),
          f"time {time}: the light is at {field(moved, 'LightPosition')}, expected {expected}")
    lamp = servermanager.Fetch(straight, idx=2)
    check(numpy.allclose(polygon_centroid(lamp), expected, atol=1e-9),
          f"time {time}: the Light output is at {polygon_centroid(lamp)}, expected {expected}")

checks.finish()

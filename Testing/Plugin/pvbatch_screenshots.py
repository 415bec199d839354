"""Rendered pictures of the first and the last light position, in pvbatch under an X server
(xvfb-run): neither is blank, and they differ where the light moved. The Elements are shown
as Apply shows them (their display colours, one exposure for the whole animation, so that
brightness compares across frames). The camera looks up at the floor of the box (seen from
outside, the colours show its lit inner side); the pictures are compared by pixel
statistics around the spots under the light (pvbatch_baseline.py compares a whole picture
with a baseline). A point light's Light output, one vertex, is drawn as a yellow disc of
about 12 pixels across where the lamp is.

    xvfb-run -a pvbatch pvbatch_screenshots.py --plugin MovingLightRadiosity.so [--keep DIR]"""
import os
import tempfile

import numpy

import plugin_test_support as support


def options(parser):
    parser.add_argument("--keep", help="also copy the two pictures into this folder")


args = support.parse_arguments(__doc__.splitlines()[0], options)

from paraview.simple import *  # noqa: F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.Screenshots")
check = checks.check

SIZE = 300
# Patches of 0.1 (about 600): less noise per element than the default 3000 for the same paths.
radiosity, sources = support.box_pipeline(PatchSize=0.1)
last = float(support.POSITIONS - 1)

view = CreateRenderView()
view.ViewSize = [SIZE, SIZE]
view.OrientationAxesVisibility = 0
view.UseColorPaletteForBackground = 0
view.Background = [0.0, 0.0, 0.0]
view.CameraPosition = [0.0, 0.0, -3.0]
view.CameraFocalPoint = [0.0, 0.0, 0.0]
view.CameraViewUp = [0.0, 1.0, 0.0]
view.CameraViewAngle = 30.0

# As Apply shows it: true colours from the filter's point array Color (Map Scalars off, unlit).
# The Light output is not shown: seen from below the floor it would hide the spots.
display = Show(radiosity, view)
check(list(display.ColorArrayName) == ["POINTS", "Color"] and display.MapScalars == 0,
      f"the Elements are shown with {list(display.ColorArrayName)}, MapScalars "
      f"{display.MapScalars}: expected the true colours of point Color")

scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()


def colours(path):
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    width, height, _ = image.GetDimensions()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(height, width, -1)
    return pixels[:, :, :3].astype(float)  # row 0 is the bottom, as on screen


def luminance(path):
    return colours(path).mean(axis=2)


def spot_on_screen(frame):
    """Display coordinates of the floor point under the light in `frame`."""
    x, y, _ = support.light_position(frame)
    renderer = view.GetRenderer()
    renderer.SetWorldPoint(x, y, support.FLOOR_Z, 1.0)
    renderer.WorldToDisplay()
    return numpy.array(renderer.GetDisplayPoint()[:2])


def disc_mean(image, centre, radius):
    rows, columns = numpy.indices(image.shape)
    inside = (columns - centre[0]) ** 2 + (rows - centre[1]) ** 2 <= radius ** 2
    return image[inside].mean()


pictures = {}
with tempfile.TemporaryDirectory(prefix="mlr-plugin-screenshots-") as folder:
    for time in (0.0, last):
        scene.AnimationTime = time
        Render(view)
        path = os.path.join(folder, f"frame_{int(time)}.png")
        SaveScreenshot(path, view, ImageResolution=[SIZE, SIZE])
        if check(os.path.isfile(path), f"no screenshot written at time {time}"):
            pictures[time] = luminance(path)
            if args.keep:
                os.makedirs(args.keep, exist_ok=True)
                os.replace(path, os.path.join(args.keep, os.path.basename(path)))
    spots = {0.0: spot_on_screen(0), last: spot_on_screen(support.POSITIONS - 1)}

if len(pictures) == 2:
    # The spot radius on screen: about the light's size seen from the camera.
    radius = 0.1 * SIZE
    for time, image in pictures.items():
        lit = (image > 10).mean()
        check(lit > 0.3, f"time {time}: only {100 * lit:.0f}% of the picture is lit (blank?)")
        check(image.std() > 5, f"time {time}: the picture is uniform (standard deviation {image.std():.1f})")
    first, final = pictures[0.0], pictures[last]
    at_first = [disc_mean(first, spots[0.0], radius), disc_mean(first, spots[last], radius)]
    at_final = [disc_mean(final, spots[0.0], radius), disc_mean(final, spots[last], radius)]
    check(at_first[0] > 1.3 * at_first[1],
          f"frame 0 is not brighter under its light ({at_first[0]:.1f}) than under the last "
          f"frame's ({at_first[1]:.1f})")
    check(at_final[1] > 1.3 * at_final[0],
          f"the last frame is not brighter under its light ({at_final[1]:.1f}) than under "
          f"frame 0's ({at_final[0]:.1f})")
    difference = numpy.abs(final - first)
    where_moved = min(disc_mean(difference, spots[0.0], radius), disc_mean(difference, spots[last], radius))
    check(where_moved > 2 * difference.mean(),
          f"the pictures differ as much everywhere ({difference.mean():.1f}) as where the light "
          f"moved ({where_moved:.1f})")
    print(f"brightness under the light at frame 0 / last: frame 0 {at_first[0]:.0f} / "
          f"{at_first[1]:.0f}, last frame {at_final[0]:.0f} / {at_final[1]:.0f}")


# --- A point light as Apply shows it ----------------------------------------------------------
# The Light output alone, seen through the box's floor: the point light's one vertex should be
# a yellow disc about 12 pixels across where the lamp is, not the 2 x 2 pixels of a vertex.
point = MovingLightRadiosity(Scene=sources["box"], Trajectory=sources["trajectory"],
                             LightType="Point", NumberOfPaths=support.TEST_PATHS)
point.UpdatePipeline(0.0)
lamp_view = CreateRenderView()
for name in ("ViewSize", "OrientationAxesVisibility", "UseColorPaletteForBackground", "Background",
             "CameraPosition", "CameraFocalPoint", "CameraViewUp", "CameraViewAngle"):
    setattr(lamp_view, name, getattr(view, name))
Show(OutputPort(point, 2), lamp_view)
lamp_view.ViewTime = 0.0
Render(lamp_view)
with tempfile.TemporaryDirectory(prefix="mlr-plugin-point-light-") as folder:
    path = os.path.join(folder, "point_light.png")
    SaveScreenshot(path, lamp_view, ImageResolution=[SIZE, SIZE])
    picture = colours(path) if check(os.path.isfile(path), "no screenshot of the point light") else None
if picture is not None:
    red, green, blue = picture[:, :, 0], picture[:, :, 1], picture[:, :, 2]
    yellow = (red > 150) & (green > 100) & (blue < 100)
    disc = numpy.pi * (12 / 2) ** 2
    check(0.5 * disc < yellow.sum() < 2 * disc,
          f"the point light covers {yellow.sum()} yellow pixels, expected a disc of about "
          f"{disc:.0f} (12 pixels across)")
    rows, columns = numpy.nonzero(yellow)
    renderer = lamp_view.GetRenderer()
    renderer.SetWorldPoint(*support.light_position(0), 1.0)
    renderer.WorldToDisplay()
    where = numpy.array(renderer.GetDisplayPoint()[:2])
    if yellow.any():
        centre = numpy.array([columns.mean(), rows.mean()])
        check(numpy.linalg.norm(centre - where) < 3,
              f"the point light is drawn at pixel {centre}, the lamp is at {where}")
    print(f"point light: {yellow.sum()} yellow pixels")

checks.finish()

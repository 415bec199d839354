"""The moving-light Cornell box in ParaView, from the shipped data to an animation on disk.

    xvfb-run -a pvpython Examples/cornell_box_animation.py [--plugin PATH] [--output DIR] [--paths N]

(without a display server, xvfb-run gives pvpython one; on a desktop, plain pvpython works.)

It does what a ParaView user does by hand: open Data/cornell_box.vtp (Scene),
cornell_light.vtp (Light) and cornell_trajectory.vtp (Trajectory, 30 positions), apply
Filters > Radiosity > Moving Light Radiosity, then save

  DIR/cornell.pvd + DIR/cornell/*.vtu   the Elements of every light position (MergeBlocks +
                                        File > Save Data with "Write Time Steps"), for ParaView,
                                        VisIt or any VTK reader;
  DIR/png/frame_0000.png ...            one picture per light position, as Apply shows it:
                                        the Elements in their display colours (point array
                                        Color: the radiosity smoothed at the points, exposed
                                        once for the whole animation, ACES filmic tone map,
                                        sRGB) and the Light output, the lamp, in yellow.

DIR defaults to output/paraview. The plugin defaults to the one built in build/ (or in
$MLR_BUILD_DIR); a plugin already loaded through PV_PLUGIN_PATH is used as it is.
"""
import argparse
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import example_support  # noqa: E402

ROOT = example_support.ROOT


def parse_arguments():
    parser = argparse.ArgumentParser(
        description="Render the moving-light Cornell box with the ParaView plugin and save "
                    "it as PNG frames and a .pvd/.vtu series.")
    parser.add_argument("--plugin", help="MovingLightRadiosity.so to load (default: the one "
                        "in the build tree, build/ or $MLR_BUILD_DIR)")
    parser.add_argument("--output", default=os.path.join("output", "paraview"),
                        help="folder for cornell.pvd, cornell/ and png/ (default: %(default)s)")
    parser.add_argument("--paths", type=int, default=600000,
                        help="effective shooting paths per light position; fewer is faster and "
                             "noisier (default: %(default)s)")
    parser.add_argument("--patch-size", type=float, default=0.0,
                        help="patch edge length in metres, 0 for about 3000 patches (default: 0)")
    parser.add_argument("--size", type=int, default=640,
                        help="picture width and height in pixels (default: %(default)s)")
    parser.add_argument("--data", default=os.path.join(ROOT, "Data"),
                        help="folder with cornell_box.vtp, cornell_light.vtp and "
                             "cornell_trajectory.vtp (default: the repository's Data/)")
    args = parser.parse_args()
    if args.paths < 1:
        parser.error(f"--paths must be at least 1, not {args.paths}")
    if args.size < 16:
        parser.error(f"--size must be at least 16 pixels, not {args.size}")
    for name in ("cornell_box.vtp", "cornell_light.vtp", "cornell_trajectory.vtp"):
        if not os.path.isfile(os.path.join(args.data, name)):
            parser.error(f"no {name} in {args.data}: give the Data/ folder with --data")
    return args, parser


args, parser = parse_arguments()
x_connection = example_support.require_display(parser, "Examples/cornell_box_animation.py")

# Only now: importing paraview.simple starts ParaView, which --help need not wait for.
import paraview.simple as pv  # noqa: E402

example_support.load_plugin(pv, parser, args.plugin)  # adds the filter to paraview.simple
MovingLightRadiosity = getattr(pv, example_support.PLUGIN_NAME)

# --- The pipeline, as built in the GUI ------------------------------------------------------
scene = pv.XMLPolyDataReader(registrationName="cornell_box.vtp",
                             FileName=[os.path.join(args.data, "cornell_box.vtp")])
light = pv.XMLPolyDataReader(registrationName="cornell_light.vtp",
                             FileName=[os.path.join(args.data, "cornell_light.vtp")])
trajectory = pv.XMLPolyDataReader(registrationName="cornell_trajectory.vtp",
                                  FileName=[os.path.join(args.data, "cornell_trajectory.vtp")])
radiosity = MovingLightRadiosity(registrationName="MovingLightRadiosity", Scene=scene,
                                 Light=light, Trajectory=trajectory, NumberOfPaths=args.paths,
                                 PatchSize=args.patch_size)

started = time.time()
radiosity.UpdatePipeline(time=0.0)
if radiosity.GetDataInformation().GetNumberOfCells() == 0:
    sys.exit("the filter produced nothing: see the error above")
times = list(radiosity.TimestepValues)
print(f"solved {len(times)} light positions, "
      f"{radiosity.GetDataInformation().GetNumberOfCells()} elements, "
      f"{args.paths} paths each, in {time.time() - started:.1f} s")

os.makedirs(args.output, exist_ok=True)

# --- The .pvd/.vtu series: every time step, from the one cached solve -----------------------
merged = pv.MergeBlocks(registrationName="Elements", Input=radiosity)
series = os.path.join(args.output, "cornell.pvd")
pv.SaveData(series, proxy=merged, WriteTimeSteps=1)
print(f"wrote {series} and {len(times)} .vtu files in {os.path.join(args.output, 'cornell')}")

# --- The pictures -----------------------------------------------------------------------------
# Shown as Apply shows them: the filter's Elements in true colours (its point array Color, Map
# Scalars off, unlit) and its Light output, the lamp where it is in each frame, in yellow.
view = example_support.picture_view(pv, args.size, [0.0, 0.0, 0.0])
room = pv.Show(radiosity, view)
lamp = pv.Show(pv.OutputPort(radiosity, 2), view)

# The Cornell box camera (35 mm lens, 25 mm film): along +z, the front face filling the view.
bounds = scene.GetDataInformation().GetBounds()
centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2 for i in range(3)]
half = max(bounds[1] - bounds[0], bounds[3] - bounds[2]) / 2
view.CameraViewAngle = 39.3
view.CameraFocalPoint = centre
view.CameraPosition = [centre[0], centre[1],
                       bounds[4] - half / math.tan(math.radians(39.3 / 2))]
view.CameraViewUp = [0.0, 1.0, 0.0]

pictures = os.path.join(args.output, "png")
example_support.save_pictures(pv, view, times, pictures, args.size)
print(f"wrote {len(times)} pictures in {pictures}")

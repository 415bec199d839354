"""The middle frame of the shipped Cornell box as Apply shows it (true colours and the yellow
lamp), compared with a committed baseline picture the way ParaView's own tests compare
theirs: vtkTesting's image difference, ParaView's default threshold (10, smtesting.Threshold).

The picture is deterministic: Seed 0 (the solve does not depend on the thread count), a
fixed camera, a 400 x 300 view, no orientation axes, black background.

    xvfb_display.py pvbatch pvbatch_baseline.py --plugin MovingLightRadiosity.so \
        [--baseline Baseline/cornell_middle_frame.png] [--update-baseline] [--keep DIR]

On failure vtkTesting writes the picture, the baseline and their difference into the
--keep folder (default: a temporary one, printed). A deliberate change of what the picture
shows (the remeshing, the solver's sampling, the tone map) needs a new baseline: look at the
picture in the --keep folder, then run again with --update-baseline and commit it."""
import math
import os
import shutil
import tempfile

import plugin_test_support as support

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
THRESHOLD = 10.0
MEAN_LEVELS = 3.0
BLOCK = 10
SIZE = (400, 300)
PATHS = 600000


def options(parser):
    parser.add_argument("--baseline", default=os.path.join(HERE, "Baseline", "cornell_middle_frame.png"))
    parser.add_argument("--update-baseline", action="store_true",
                        help="write the picture as the new baseline instead of comparing")
    parser.add_argument("--keep", help="folder for the picture and, on failure, the difference")
    parser.add_argument("--exposure", type=float, default=0.0,
                        help="Exposure for the picture (to see that the comparison can fail)")
    parser.add_argument("--seed", type=int, default=0,
                        help="Seed for the picture (to measure what noise alone changes)")


args = support.parse_arguments(__doc__.splitlines()[0], options)

from paraview.simple import *  # noqa: F401,F403
from vtkmodules.vtkIOImage import vtkPNGReader
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkTestingRendering import vtkTesting
import numpy

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.Baseline")
check = checks.check

data = os.path.join(ROOT, "Data")
scene = XMLPolyDataReader(FileName=[os.path.join(data, "cornell_box.vtp")])
light = XMLPolyDataReader(FileName=[os.path.join(data, "cornell_light.vtp")])
trajectory = XMLPolyDataReader(FileName=[os.path.join(data, "cornell_trajectory.vtp")])
radiosity = MovingLightRadiosity(Scene=scene, Light=light, Trajectory=trajectory,
                                 NumberOfPaths=PATHS, Seed=args.seed, Exposure=args.exposure)
radiosity.UpdatePipelineInformation()
times = list(radiosity.TimestepValues)
middle = times[len(times) // 2]

view = CreateRenderView()
view.ViewSize = list(SIZE)
view.OrientationAxesVisibility = 0
view.UseColorPaletteForBackground = 0
view.Background = [0.0, 0.0, 0.0]
Show(radiosity, view)
Show(OutputPort(radiosity, 2), view)
# The Cornell box camera: along +z, 39.3 degrees, the box's open front filling the height.
scene.UpdatePipeline()
bounds = scene.GetDataInformation().GetBounds()
centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2 for i in range(3)]
half = (bounds[3] - bounds[2]) / 2
view.CameraViewAngle = 39.3
view.CameraFocalPoint = centre
view.CameraPosition = [centre[0], centre[1], bounds[4] - half / math.tan(math.radians(39.3 / 2))]
view.CameraViewUp = [0.0, 1.0, 0.0]
view.ViewTime = middle



def pixels(path):
    image = vtkPNGReader()
    image.SetFileName(path)
    image.Update()
    width, height, _ = image.GetOutput().GetDimensions()
    values = vtk_to_numpy(image.GetOutput().GetPointData().GetScalars())
    return values.reshape(height, width, -1)[:, :, :3].astype(float)


def blocks(image):
    height, width = (image.shape[0] // BLOCK) * BLOCK, (image.shape[1] // BLOCK) * BLOCK
    tiles = image[:height, :width].reshape(height // BLOCK, BLOCK, width // BLOCK, BLOCK, -1)
    return tiles.mean(axis=(1, 3))


folder = args.keep or tempfile.mkdtemp(prefix="mlr-plugin-baseline-")
os.makedirs(folder, exist_ok=True)
picture = os.path.join(folder, "cornell_middle_frame.png")
SaveScreenshot(picture, view, ImageResolution=list(SIZE))

if args.update_baseline:
    os.makedirs(os.path.dirname(args.baseline), exist_ok=True)
    shutil.copyfile(picture, args.baseline)
    print(f"wrote the baseline {args.baseline}")
elif check(os.path.isfile(args.baseline), f"no baseline at {args.baseline}: run with --update-baseline"):
    reader = vtkPNGReader()
    reader.SetFileName(picture)
    reader.Update()
    testing = vtkTesting()
    for argument in ("-V", args.baseline, "-T", folder):
        testing.AddArgument(argument)
    passed = testing.RegressionTest(reader, THRESHOLD) == vtkTesting.PASSED
    check(passed, f"the middle frame differs from {args.baseline} beyond the threshold "
          f"{THRESHOLD}: see {folder}")
    # vtkImageDifference forgives each pixel up to a large colour difference, to absorb
    # rasterisation: a third of a stop of exposure or another tone curve passes it. The
    # colours are what this picture is about, so they are held closer as well, on the means
    # of BLOCK x BLOCK pixel blocks, where pixel-level noise averages out: another seed (the
    # noise of another random stream, as a change in Core's sampling would give) moves them by
    # about 1.6 levels of 255 on average, Exposure -0.15 by about 4, +0.3 by about 8.
    got, expected = blocks(pixels(picture)), blocks(pixels(args.baseline))
    if check(got.shape == expected.shape, f"picture {got.shape}, baseline {expected.shape}"):
        mean = float(numpy.abs(got - expected).mean())
        check(mean <= MEAN_LEVELS, f"the colours differ from the baseline by {mean:.2f} levels on "
              f"average over {BLOCK} x {BLOCK} blocks (at most {MEAN_LEVELS}): see {folder}")
        print(f"mean colour difference {mean:.2f} levels over {BLOCK} x {BLOCK} blocks "
              f"(at most {MEAN_LEVELS})")
    print(f"image difference {testing.GetImageDifference():.2f} (threshold {THRESHOLD})")
    if passed and not args.keep:
        shutil.rmtree(folder, ignore_errors=True)

checks.finish()

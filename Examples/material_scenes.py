"""Scene files with their own materials in ParaView: the Cornell box OBJ + MTL and a glTF room,
each lit by its own lamp moving along a straight path.

    xvfb-run -a pvpython Examples/material_scenes.py [--plugin PATH] [--output DIR] [--paths N]

(without a display server, xvfb-run gives pvpython one; on a desktop, plain pvpython works.)

It does what a ParaView user does by hand, for each scene:
  File > Open the scene with "Radiosity scene with materials" (RadiositySceneReader): every
  cell gets its material's colour (Reflectance), emission (Emission) and MaterialId;
  Filters > Radiosity > Moving Light Radiosity with no Light input and Light Material set to
  the lamp's material: its polygons leave the scene and become the light, whose centroid goes
  from Path Start to Path End in Number Of Positions steps, with the power the material emits
  (pi x radiance x area);
then saves

  DIR/cornell.pvd + DIR/cornell/*.vtu   Data/CornellBox-Original.obj, lamp material "light"
  DIR/room.pvd + DIR/room/*.vtu         Data/room.gltf (Data/make_gltf_room.py), lamp "panel"
  DIR/png/cornell/frame_0000.png ...    one picture per position, in the scene's own colours
  DIR/png/room/frame_0000.png ...       (the Elements' display colours) with the lamp in yellow

DIR defaults to output/materials. The plugin defaults to the one built in build/ (or in
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

# name, file in Data/, light material, path start, path end, camera direction (from the
# scene's centre towards the camera), view up. Both files are y up with an open side to +z.
SCENES = [
    ("cornell", "CornellBox-Original.obj", "light",
     (-0.5, 1.9641, -0.4), (0.5, 1.9641, 0.4)),
    ("room", "room.gltf", "panel",
     (0.8, 2.49, 1.0), (3.2, 2.49, 2.0)),
]
VIEW_ANGLE = 39.3  # the Cornell box camera's (35 mm lens, 25 mm film)


def parse_arguments():
    parser = argparse.ArgumentParser(
        description="Animate the Cornell box OBJ and a glTF room, each with its own materials and "
                    "lamp, with the ParaView plugin; save PNG frames and .pvd/.vtu series.")
    parser.add_argument("--plugin", help="MovingLightRadiosity.so to load (default: the one "
                        "in the build tree, build/ or $MLR_BUILD_DIR)")
    parser.add_argument("--output", default=os.path.join("output", "materials"),
                        help="folder for the series and png/ (default: %(default)s)")
    parser.add_argument("--paths", type=int, default=600000,
                        help="effective shooting paths per light position; fewer is faster and "
                             "noisier (default: %(default)s)")
    parser.add_argument("--frames", type=int, default=30,
                        help="light positions per scene (default: %(default)s)")
    parser.add_argument("--size", type=int, default=512,
                        help="picture width and height in pixels (default: %(default)s)")
    parser.add_argument("--data", default=os.path.join(ROOT, "Data"),
                        help="folder with CornellBox-Original.obj/.mtl and room.gltf "
                             "(default: the repository's Data/)")
    args = parser.parse_args()
    if args.paths < 1:
        parser.error(f"--paths must be at least 1, not {args.paths}")
    if args.frames < 1:
        parser.error(f"--frames must be at least 1, not {args.frames}")
    if args.size < 16:
        parser.error(f"--size must be at least 16 pixels, not {args.size}")
    for name in ("CornellBox-Original.obj", "CornellBox-Original.mtl", "room.gltf"):
        if not os.path.isfile(os.path.join(args.data, name)):
            parser.error(f"no {name} in {args.data}: give the Data/ folder with --data "
                         f"(room.gltf: /usr/bin/python3 Data/make_gltf_room.py)")
    return args, parser


args, parser = parse_arguments()
x_connection = example_support.require_display(parser, "Examples/material_scenes.py")

# Only now: importing paraview.simple starts ParaView, which --help need not wait for.
import paraview.simple as pv  # noqa: E402

example_support.load_plugin(pv, parser, args.plugin)
MovingLightRadiosity = getattr(pv, example_support.PLUGIN_NAME)
os.makedirs(args.output, exist_ok=True)

for name, file, material, start, end in SCENES:
    # --- File > Open, then the filter with the lamp taken from the scene ----------------------
    scene = pv.RadiositySceneReader(registrationName=file,
                                    FileName=os.path.join(args.data, file))
    radiosity = MovingLightRadiosity(registrationName=f"MovingLightRadiosity ({name})",
                                     Scene=scene, LightMaterial=material,
                                     # from this start, not where the scene has the lamp
                                     PathFromLightMaterial=0, PathStart=list(start),
                                     PathEnd=list(end), NumberOfPositions=args.frames,
                                     NumberOfPaths=args.paths)
    started = time.time()
    radiosity.UpdatePipeline(time=0.0)
    if radiosity.GetDataInformation().GetNumberOfCells() == 0:
        sys.exit(f"{file}: the filter produced nothing: see the error above")
    times = list(radiosity.TimestepValues) or [0.0]
    print(f"{file}: solved {len(times)} positions of the lamp '{material}', "
          f"{radiosity.GetDataInformation().GetNumberOfCells()} elements, {args.paths} paths "
          f"each, in {time.time() - started:.1f} s")

    # --- The .pvd/.vtu series ----------------------------------------------------------------
    merged = pv.MergeBlocks(registrationName=f"Elements ({name})", Input=radiosity)
    series = os.path.join(args.output, name + ".pvd")
    pv.SaveData(series, proxy=merged, WriteTimeSteps=1)
    print(f"wrote {series}")

    # --- The pictures: the Elements in their display colours, the lamp in yellow --------------
    view = example_support.picture_view(pv, args.size, [0.0, 0.0, 0.0])
    pv.Show(radiosity, view)
    pv.Show(pv.OutputPort(radiosity, 2), view)
    # Looking along -z into the open side, the front face filling the view.
    bounds = scene.GetDataInformation().GetBounds()
    centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2 for i in range(3)]
    half = max(bounds[1] - bounds[0], bounds[3] - bounds[2]) / 2
    view.CameraViewAngle = VIEW_ANGLE
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[0], centre[1],
                           bounds[5] + half / math.tan(math.radians(VIEW_ANGLE / 2))]
    view.CameraViewUp = [0.0, 1.0, 0.0]

    pictures = os.path.join(args.output, "png", name)
    example_support.save_pictures(pv, view, times, pictures, args.size)
    print(f"wrote {len(times)} pictures in {pictures}")
    # The next scene gets a pipeline and a view of its own, as a new ParaView state would.
    pv.Delete(view)
    for proxy in (merged, radiosity, scene):
        pv.Delete(proxy)

"""Shared by the plugin's pvbatch/pvpython test scripts: finding and loading the plugin, the
pipeline built from ParaView sources only, and failure bookkeeping.

The scripts take the plugin from --plugin PATH or the MLR_PLUGIN environment variable (ctest
sets both from the build tree) and exit non-zero with one line per failed check."""
import argparse
import os
import sys

# A closed unit box centred on the origin (ParaView's Box source: outward normals) lit from
# inside by a 0.2 x 0.2 plane 0.1 below its top, moving along a diagonal in 10 steps.
LIGHT_Z = 0.4
LIGHT_HALF = 0.1
PATH_START = (-0.3, -0.3, LIGHT_Z)
PATH_END = (0.3, 0.3, LIGHT_Z)
POSITIONS = 10
FLOOR_Z = -0.5
# Enough paths for the light's footprint to stand out, few enough for a second's solve.
TEST_PATHS = 20000


def parse_arguments(description, extra=None):
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--plugin", default=os.environ.get("MLR_PLUGIN"),
                        help="MovingLightRadiosity.so to load (default: $MLR_PLUGIN)")
    if extra:
        extra(parser)
    args = parser.parse_args()
    if not args.plugin:
        parser.error("give the plugin with --plugin PATH or the MLR_PLUGIN environment variable")
    if not os.path.isfile(args.plugin):
        parser.error(f"no plugin at {args.plugin}: build the project first")
    return args


_filter = None


def load_plugin(path, namespace):
    """LoadPlugin into `namespace` (the script's globals), as a user would."""
    global _filter
    from paraview.simple import LoadPlugin
    LoadPlugin(path, remote=False, ns=namespace)
    if "MovingLightRadiosity" not in namespace:
        sys.exit(f"LoadPlugin({path!r}) did not define MovingLightRadiosity")
    _filter = namespace["MovingLightRadiosity"]


def light_position(frame):
    """The light centroid the Line trajectory gives for `frame`."""
    f = frame / (POSITIONS - 1)
    return tuple(a + f * (b - a) for a, b in zip(PATH_START, PATH_END))


def box_pipeline(**properties):
    """Box as Scene, a Plane facing down (-z) as Light, a Line with resolution 9 as
    Trajectory; returns (filter, sources) with the sources by name."""
    from paraview import simple
    box = simple.Box()
    x, y, z = -LIGHT_HALF, -LIGHT_HALF, LIGHT_Z
    # normal = (Point1 - Origin) x (Point2 - Origin) = (+y) x (+x) = -z: towards the floor.
    light = simple.Plane(Origin=[x, y, z], Point1=[x, y + 2 * LIGHT_HALF, z],
                         Point2=[x + 2 * LIGHT_HALF, y, z])
    trajectory = simple.Line(Point1=list(PATH_START), Point2=list(PATH_END),
                             Resolution=POSITIONS - 1)
    properties.setdefault("NumberOfPaths", TEST_PATHS)
    radiosity = _filter(Scene=box, Light=light, Trajectory=trajectory,
                        **properties)
    return radiosity, {"box": box, "light": light, "trajectory": trajectory}


def generic_decorators(prop):
    hints = prop.GetHints()
    for i in range(hints.GetNumberOfNestedElements() if hints else 0):
        element = hints.GetNestedElement(i)
        if element.GetName() == "PropertyWidgetDecorator" and \
                element.GetAttribute("type") == "GenericDecorator":
            yield element


def decorator_matches(source, decorator):
    """Whether ParaView 5.11's GenericDecorator (pqGenericPropertyWidgetDecorator::valueMatch)
    shows or enables its widget: the named property's unchecked element `index` (the value in
    the panel before Apply) as vtkVariant spells it, equal to `value` or to one of the
    space-separated `values`; inverse="1" negates. Int and string properties only: the ones
    the XML depends on, whose spelling is exact."""
    from vtkmodules.vtkCommonCore import vtkVariant  # pvbatch's, once ParaView is set up

    other = source.GetProperty(decorator.GetAttribute("property"))
    index = int(decorator.GetAttribute("index") or 0)
    if other.IsA("vtkSMIntVectorProperty") or other.IsA("vtkSMStringVectorProperty"):
        value = vtkVariant(other.GetUncheckedElement(index)).ToString()
    else:
        raise TypeError(f"{other.GetXMLName()} is a {other.GetClassName()}")
    given = decorator.GetAttribute("value")
    status = value in ([given] if given is not None else decorator.GetAttribute("values").split(" "))
    return status != (decorator.GetAttribute("inverse") == "1")


def shown(source, name):
    """Whether the panel shows property `name` of `source` (a proxy) for the unchecked values
    of the others: ParaView shows a widget when every visibility decorator of it agrees."""
    return all(decorator_matches(source, d)
               for d in generic_decorators(source.GetProperty(name))
               if d.GetAttribute("mode") == "visibility")


class PrintedMessages:
    """What VTK prints while in a `with` block (errors and warnings, ParaView's generic warnings
    from vtkGenericWarningMacro too): `text` so far. A vtkStringOutputWindow stands in for the
    output window meanwhile; ParaView's log on stderr still shows them."""

    def __enter__(self):
        from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
        self._previous = vtkOutputWindow.GetInstance()
        self._window = vtkStringOutputWindow()
        vtkOutputWindow.SetInstance(self._window)
        return self

    def __exit__(self, *exception):
        from vtkmodules.vtkCommonCore import vtkOutputWindow
        vtkOutputWindow.SetInstance(self._previous)
        return False

    @property
    def text(self):
        return self._window.GetOutput()


class Checks:
    """Collects failures so that one run reports every broken expectation."""

    def __init__(self, name):
        self.name = name
        self.failures = []

    def check(self, condition, message):
        if not condition:
            self.failures.append(message)
        return condition

    def finish(self):
        if self.failures:
            print(f"{self.name}: {len(self.failures)} failure(s)", file=sys.stderr)
            for failure in self.failures:
                print("  " + failure, file=sys.stderr)
            sys.exit(1)
        print(f"{self.name}: OK")
        sys.stdout.flush()

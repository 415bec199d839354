"""The plugin's proxy as ParaView users meet it, checked in pvbatch:

- the menu hint (Filters > Radiosity), the input ports (Scene, Light, optional Trajectory and Sensors)
  and the data types they accept, the output port names (Elements, Patches, Light, Sensors);
- every property: a label that is also its paraview.simple name, documentation, a domain,
  the VTK filter's default, the filter's range (refused by name just outside), advanced or not;
- every property's documentation names its unit (or says it has none) and its effect on
  the cost of a solve;
- the panel's decorators name properties of the filter, and the Light Material's own
  properties (Light Power From Material, Path From Light Material) are shown only while a
  material is named, as ParaView's GenericDecorator evaluates them;
- what the first Apply shows: TimestepValues and the time keeper with one step per light
  position, the Elements in the true colours of point Color (Map Scalars off), the Patches
  not shown, the Light shown (pvbatch_display.py checks the display in detail).

    pvbatch --force-offscreen-rendering pvbatch_proxy.py --plugin MovingLightRadiosity.so

The VTK defaults and ranges come from the Python package (PYTHONPATH=<build>/lib/python3/
dist-packages), so that the XML cannot drift from vtkMovingLightRadiosity."""
import plugin_test_support as support

args = support.parse_arguments(__doc__.splitlines()[0])

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403 (LoadPlugin adds the filter here)

support.load_plugin(args.plugin, globals())
checks = support.Checks("Plugin.Proxy")
check = checks.check

import os  # noqa: E402
import sys  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from movinglightradiosity import vtkMovingLightRadiosity  # noqa: E402
from vtk_messages import recorded  # noqa: E402
from vtkmodules.vtkCommonCore import vtkDoubleArray  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkPolyData  # noqa: E402
from vtkmodules.vtkFiltersSources import vtkCubeSource  # noqa: E402


def glowing_box_filter():
    """The filter on a box that lights itself: every property in range would solve."""
    cube = vtkCubeSource()
    cube.Update()
    box = cube.GetOutput()
    emission = vtkDoubleArray()
    emission.SetName("Emission")
    emission.SetNumberOfComponents(3)
    for _ in range(box.GetNumberOfCells()):
        emission.InsertNextTuple3(1, 1, 1)
    box.GetCellData().AddArray(emission)
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetInputData(vtkMovingLightRadiosity.SCENE_PORT, box)
    return radiosity


def refused(name, value):
    """The errors naming `name` of the filter given `value` for it, on an empty Scene: the
    properties' ranges are checked before anything else, and nothing is solved."""
    probe = vtkMovingLightRadiosity()
    probe.SetInputData(vtkMovingLightRadiosity.SCENE_PORT, vtkPolyData())
    getattr(probe, "Set" + name)(value)
    errors = recorded(probe, "ErrorEvent")
    probe.Update()
    return [e for e in errors if name in e]


def range_domain(prop):
    """The property's one range domain (int or double), or None."""
    found = [d for d in domains(prop) if d.IsA("vtkSMIntRangeDomain") or
             d.IsA("vtkSMDoubleRangeDomain")]
    return found[0] if len(found) == 1 else None


radiosity, sources = support.box_pipeline()
proxy = radiosity.SMProxy

# --- Menu, ports --------------------------------------------------------------------------
check(proxy.GetXMLGroup() == "filters" and proxy.GetXMLLabel() == "Moving Light Radiosity",
      f"proxy {proxy.GetXMLGroup()}/{proxy.GetXMLLabel()}, expected filters/Moving Light Radiosity")
menu = proxy.GetHints().FindNestedElementByName("ShowInMenu") if proxy.GetHints() else None
check(menu is not None and menu.GetAttribute("category") == "Radiosity",
      "no <ShowInMenu category=\"Radiosity\"/> hint: the filter would not be in Filters > Radiosity")
for port, name in enumerate(("Elements", "Patches", "Light", "Sensors")):
    check(proxy.GetOutputPortName(port) == name,
          f"output port {port} is named {proxy.GetOutputPortName(port)!r}, expected {name!r}")


def domains(prop):
    iterator = prop.NewDomainIterator()
    iterator.Begin()
    while not iterator.IsAtEnd():
        yield iterator.GetDomain()
        iterator.Next()


# What each port accepts, asked the way the GUI's input dialog asks: polygons (Box), a
# tetrahedral unstructured grid (a point set, not polygons), an image (neither) and a
# multiblock. The Scene and the Light take the surface of any of them.
candidates = {"polydata": Box(), "tetrahedra": Tetrahedralize(Input=Wavelet(WholeExtent=[0, 2] * 3)),
              "image": Wavelet(WholeExtent=[0, 2] * 3),
              "multiblock": GroupDatasets(Input=[Box(), Sphere()])}
for candidate in candidates.values():
    candidate.UpdatePipeline()
for port, (name, accepted, optional) in enumerate((("Scene", set(candidates), False),
                                                   ("Light", set(candidates), True),
                                                   ("Trajectory", {"polydata", "tetrahedra"}, True),
                                                   ("Sensors", {"polydata", "tetrahedra"}, True))):
    prop = proxy.GetProperty(name)
    if not check(prop is not None and prop.IsA("vtkSMInputProperty"), f"no input property {name}"):
        continue
    check(prop.GetPortIndex() == port, f"input {name} on port {prop.GetPortIndex()}, expected {port}")
    check(prop.GetXMLLabel() == name, f"input {name} labelled {prop.GetXMLLabel()!r}")
    for kind, candidate in candidates.items():
        if kind == "multiblock" and name not in ("Scene", "Light"):
            continue  # ParaView offers a composite of accepted leaves to any port
        prop.RemoveAllUncheckedProxies()
        prop.AddUncheckedInputConnection(candidate.SMProxy, 0)
        takes = bool(prop.IsInDomains())
        check(takes == (kind in accepted),
              f"input {name} {'accepts' if takes else 'refuses'} {kind}, expected the opposite")
    prop.RemoveAllUncheckedProxies()
    hints = prop.GetHints()
    is_optional = bool(hints and hints.FindNestedElementByName("Optional"))
    check(is_optional == optional, f"input {name} optional: {is_optional}, expected {optional}")
    check(bool(prop.GetDocumentation() and prop.GetDocumentation().GetDescription().strip()),
          f"input {name} has no documentation")

# --- Properties ---------------------------------------------------------------------------
ADVANCED = {"Seed", "NumberOfThreads", "FirstBounceSurvival", "GatheringRatio", "MemoryLimit",
            "ErrorBatches", "TimeLimit"}
BOOLEANS = {"TwoSided", "ReuseShooting", "ReuseGathering", "AimAtPoint", "LightPowerFromMaterial"}
# Free text (names of arrays and materials): no domain to check against.
STRINGS = {"LightMaterial", "ReflectanceArrayName", "EmissionArrayName"}
EXPECTED = {"LightPower", "NumberOfPaths", "GatheringRatio", "FirstBounceSurvival",
            "ReuseShooting", "ReuseGathering", "PatchSize", "Seed", "NumberOfThreads",
            "TwoSided", "PathStart", "PathEnd", "NumberOfPositions", "MemoryLimit", "Exposure",
            "LightType", "SunIrradiance", "LightMaterial", "LightPowerFromMaterial", "AimAtPoint",
            "AimPoint", "ReflectanceArrayName", "EmissionArrayName", "LuminousEfficacy"}
# Every property's documentation ends with its unit and its effect on the cost of a solve.
UNIT_TAG, COST_TAG = "Unit:", "Cost:"
# The luminaire's properties.
EXPECTED |= {"LightDistributionFile", "SpotHalfAngle", "SpotSoftEdge", "LightFluxLumens",
             "LightFluxFromFile"}
BOOLEANS |= {"LightFluxFromFile"}
STRINGS |= {"LightDistributionFile"}
# The error estimate's properties.
EXPECTED |= {"ErrorBatches", "TargetRelativeError", "TimeLimit"}
# The sky's properties.
EXPECTED |= {"SkyModel", "SkyDiffuseHorizontal", "Up"}
# The paths' shares over the light's positions.
EXPECTED |= {"BalanceFrames"}
BOOLEANS |= {"BalanceFrames"}
ADVANCED |= {"BalanceFrames"}
# The sensors' properties.
EXPECTED |= {"DaylightAutonomyThreshold", "SensorRays"}
# Where a Light Material's lamp starts without a Trajectory.
EXPECTED |= {"PathFromLightMaterial"}
BOOLEANS |= {"PathFromLightMaterial"}
# Defaults ParaView sets apart from the filter's on purpose (XML, VTK): ParaView's PathStart
# comes from the Scene's bounds, not the lamp, while a script's PathStart keeps its meaning.
PARAVIEW_OWN = {"PathFromLightMaterial": ([1.0], [0.0])}
# The chunks of a long animation.
EXPECTED |= {"FramesPerChunk", "ChunkOverlap", "CachedChunks"}
ADVANCED |= {"FramesPerChunk", "ChunkOverlap", "CachedChunks"}
# Values inside a domain that the filter refuses, which a range domain (one interval) cannot
# leave out, and what the documentation says of them.
INSIDE_REFUSED = {"FramesPerChunk": {1: "1 is refused"}}
# Filter bounds a domain leaves out: a single number with both bounds is shown as a slider
# between them, of no use from 0 to 1e30 lm or to 1000000 frames (ChunkOverlap's own limit is
# half of Frames Per Chunk); NumberOfPaths is an int property, whose panel stops at 2^31 - 1
# paths, below the filter's 1e11.
WIDER = {"LightFluxLumens", "ChunkOverlap", "NumberOfPaths"}
vtk_defaults = vtkMovingLightRadiosity()
# The pipeline above changed NumberOfPaths: a proxy fresh from the XML holds the defaults.
pristine = servermanager.filters.MovingLightRadiosity().SMProxy
python_names = set(radiosity.ListProperties())
found = set()
iterator = proxy.NewPropertyIterator()
iterator.Begin()
while not iterator.IsAtEnd():
    name, prop = iterator.GetKey(), iterator.GetProperty()
    iterator.Next()
    if prop.GetInformationOnly() or prop.IsA("vtkSMInputProperty"):
        continue
    found.add(name)
    where = f"property {name}"
    check(prop.GetXMLLabel() and prop.GetXMLLabel().replace(" ", "") == name,
          f"{where}: label {prop.GetXMLLabel()!r} does not spell the VTK name (paraview.simple uses it)")
    check(name in python_names, f"{where}: not in paraview.simple's ListProperties()")
    doc = prop.GetDocumentation()
    check(doc is not None and len(doc.GetDescription().split()) >= 8,
          f"{where}: documentation missing or shorter than a sentence")
    text = doc.GetDescription() if doc is not None else ""
    for tag, what in ((UNIT_TAG, "its unit"), (COST_TAG, "its effect on the cost")):
        said = text.split(tag, 1)[1].split(".", 1)[0].strip() if tag in text else ""
        check(len(said.split()) >= 1, f"{where}: the documentation does not give {what} ({tag!r})")
    own_domains = list(domains(prop))
    check(own_domains or name in STRINGS, f"{where}: no domain")
    visibility = prop.GetPanelVisibility()
    expected_visibility = "advanced" if name in ADVANCED else "default"
    check(visibility == expected_visibility, f"{where}: panel_visibility {visibility!r}, expected "
          f"{expected_visibility!r}")
    if name in BOOLEANS:
        check(any(d.IsA("vtkSMBooleanDomain") for d in own_domains), f"{where}: not a checkbox")

    getter = getattr(vtk_defaults, "Get" + name, None)
    if not check(getter is not None, f"{where}: vtkMovingLightRadiosity has no Get{name}"):
        continue
    vtk_value = getter()
    vtk_value = list(vtk_value) if isinstance(vtk_value, tuple) else [vtk_value]
    default = pristine.GetProperty(name)
    xml_value = [default.GetElement(i) for i in range(default.GetNumberOfElements())]
    if name in PARAVIEW_OWN:
        check(([float(v) for v in xml_value], [float(v) for v in vtk_value]) == PARAVIEW_OWN[name],
              f"{where}: XML default {xml_value}, VTK default {vtk_value}, expected "
              f"{PARAVIEW_OWN[name]}")
    elif name in STRINGS:
        check([str(v) for v in xml_value] == [str(v) for v in vtk_value],
              f"{where}: XML default {xml_value}, VTK default {vtk_value}")
    else:
        check([float(v) for v in xml_value] == [float(v) for v in vtk_value],
              f"{where}: XML default {xml_value}, VTK default {vtk_value}")

    # A value just outside the domain is kept as given, and the update refuses it by name:
    # the panel's range is the filter's, and nothing is silently changed.
    for domain in own_domains:
        if prop.GetNumberOfElements() != 1 or not (domain.IsA("vtkSMIntRangeDomain") or
                                                   domain.IsA("vtkSMDoubleRangeDomain")):
            continue
        outside = []
        if domain.GetMinimumExists(0):
            low = domain.GetMinimum(0)
            outside.append(low - 1 if domain.IsA("vtkSMIntRangeDomain") else low - 1e-6 - abs(low))
        if domain.GetMaximumExists(0):
            outside.append(domain.GetMaximum(0) + 1)
        for value in outside:
            probe = glowing_box_filter()
            getattr(probe, "Set" + name)(value)
            got = getattr(probe, "Get" + name)()
            check(got == value, f"{where}: the filter turns {value} into {got}")
            errors = recorded(probe, "ErrorEvent")
            probe.Update()
            check(any(name in e for e in errors),
                  f"{where}: {value}, outside the domain, is not refused by name: {errors}")

    # And the domain holds nothing the filter refuses: its bounds, and a count's values next
    # to them, pass the filter's range check. A range domain cannot leave out a value inside
    # it: those the filter refuses there are in INSIDE_REFUSED, and the documentation says so.
    domain = range_domain(prop)
    if prop.GetNumberOfElements() == 1 and domain is not None:
        counts = domain.IsA("vtkSMIntRangeDomain")
        inside = []
        if domain.GetMinimumExists(0):
            inside += [domain.GetMinimum(0)] + ([domain.GetMinimum(0) + 1] if counts else [])
        if domain.GetMaximumExists(0):
            inside += [domain.GetMaximum(0)] + ([domain.GetMaximum(0) - 1] if counts else [])
        for value in inside:
            errors = refused(name, value)
            said = INSIDE_REFUSED.get(name, {}).get(value)
            if said is None:
                check(not errors, f"{where}: {value}, in the domain, is refused: {errors}")
            else:
                check(errors, f"{where}: {value} is listed as refused, but the filter takes it")
                check(said in text, f"{where}: the documentation does not say {said!r}")
check(found == EXPECTED, f"properties {sorted(found)}, expected {sorted(EXPECTED)}")

# The domains' bounds are the filter's table (vtkMovingLightRadiosity::GetPropertyRange), or
# absent where the filter has none (VTK_INT_MAX for a count, the largest double), but for
# WIDER, whose bound is left out for the reason given: above it the filter refuses by name.
for name in sorted(found):
    bounds = [0.0, 0.0]
    if not vtkMovingLightRadiosity.GetPropertyRange(name, bounds):
        continue
    where = f"property {name}"
    domain = range_domain(proxy.GetProperty(name))
    if not check(domain is not None, f"{where}: no range domain for the filter's {bounds}"):
        continue
    counts = domain.IsA("vtkSMIntRangeDomain")
    unbounded = bounds[1] >= (2 ** 31 - 1 if counts else sys.float_info.max)
    low = domain.GetMinimum(0) if domain.GetMinimumExists(0) else None
    high = domain.GetMaximum(0) if domain.GetMaximumExists(0) else None
    check(low == bounds[0], f"{where}: the domain's minimum is {low}, the filter's {bounds[0]}")
    if name in WIDER:
        check(high is None, f"{where}: listed in WIDER, but the domain has a maximum {high}")
        above = int(bounds[1]) + 1 if counts else 2 * bounds[1]
        check(refused(name, above), f"{where}: {above}, above the filter's maximum, is taken")
    else:
        check(high == (None if unbounded else bounds[1]),
              f"{where}: the domain's maximum is {high}, the filter's {bounds[1]}")
# The light power's bound is the one the filter's table gives the lumens (MaximumLightPower).
bounds = [0.0, 0.0]
vtkMovingLightRadiosity.GetPropertyRange("LightFluxLumens", bounds)
domain = range_domain(proxy.GetProperty("LightPower"))
check(domain is not None and
      all(domain.GetMaximumExists(i) and domain.GetMaximum(i) == bounds[1] for i in range(3)),
      f"property LightPower: its domain does not end at the filter's {bounds[1]} W per channel")


# --- Shown when they apply ----------------------------------------------------------------
# The panel silently ignores a decorator naming no property of the proxy, and the widget is
# then always there: every decorator must name one, in a mode ParaView knows.
iterator = pristine.NewPropertyIterator()
iterator.Begin()
while not iterator.IsAtEnd():
    name, prop = iterator.GetKey(), iterator.GetProperty()
    iterator.Next()
    for decorator in support.generic_decorators(prop):
        depends = decorator.GetAttribute("property")
        check(pristine.GetProperty(depends) is not None,
              f"property {name}: its decorator depends on {depends!r}, no property of the filter")
        check(decorator.GetAttribute("mode") in ("visibility", "enabled_state"),
              f"property {name}: decorator mode {decorator.GetAttribute('mode')!r}")

# The material's own properties are hidden until a Light Material is named, and leave again
# when it is cleared; their defaults are checked above.
for name in ("LightPowerFromMaterial", "PathFromLightMaterial"):
    prop = pristine.GetProperty(name)
    rules = [d for d in support.generic_decorators(prop) if d.GetAttribute("mode") == "visibility"]
    if not check(len(rules) == 1, f"property {name}: {len(rules)} visibility decorators, "
                 "expected one, on Light Material"):
        continue
    material = pristine.GetProperty("LightMaterial")
    shown = {}
    for typed in ("", "light", ""):
        material.SetUncheckedElement(0, typed)
        shown.setdefault(typed, []).append(support.decorator_matches(pristine, rules[0]))
    material.ClearUncheckedElements()
    check(shown == {"": [False, False], "light": [True]},
          f"property {name}: shown {shown} by Light Material, expected only when one is named")

# The directional light (the sun) has Sun Irradiance for its power and no aim.
light_type, aim = pristine.GetProperty("LightType"), pristine.GetProperty("AimAtPoint")
for kind in range(4):
    light_type.SetUncheckedElement(0, kind)
    for aiming in (0, 1):
        aim.SetUncheckedElement(0, aiming)
        for name, expected in (("LightPower", kind != 1), ("AimAtPoint", kind != 1),
                               ("AimPoint", kind != 1 and aiming == 1),
                               ("SunIrradiance", kind == 1)):
            actual = support.shown(pristine, name)
            check(actual == expected, f"{name} is {'shown' if actual else 'hidden'} for "
                  f"LightType {kind}, AimAtPoint {aiming}: expected the opposite")
light_type.ClearUncheckedElements()
aim.ClearUncheckedElements()

# --- The first Apply ----------------------------------------------------------------------
radiosity.UpdatePipeline()
timesteps = list(radiosity.TimestepValues)
check(timesteps == [float(i) for i in range(support.POSITIONS)],
      f"TimestepValues {timesteps}, expected 0..{support.POSITIONS - 1}")
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
keeper_steps = list(GetTimeKeeper().TimestepValues)
check(keeper_steps == timesteps, f"the time keeper has {keeper_steps}, expected {timesteps}")
check(scene.PlayMode == "Snap To TimeSteps", f"animation play mode {scene.PlayMode!r}")

# pqApplyBehavior shows each output port with ShowInPreferredView: do the same.
from paraview.modules.vtkRemotingViews import vtkSMParaViewPipelineControllerWithRendering

view = CreateRenderView()
controller = vtkSMParaViewPipelineControllerWithRendering()
shown = [controller.ShowInPreferredView(proxy, port, view.SMProxy) for port in (0, 1, 2)]
check(shown[0] is not None, "Apply would not show the Elements output")
check(shown[1] is None, "Apply would show the Patches output on top of the Elements")
check(shown[2] is not None, "Apply would not show the Light output")
display = GetDisplayProperties(radiosity, view)
check(list(display.ColorArrayName) == ["POINTS", "Color"],
      f"the Elements are coloured by {list(display.ColorArrayName)}, expected point Color")
check(display.MapScalars == 0, "the Elements' Color goes through a colour map (Map Scalars on)")

checks.finish()

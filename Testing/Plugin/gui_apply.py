"""Inside Debian's paraview GUI (xvfb-run -a paraview --dr --script=gui_apply.py), with the
plugin loaded through PV_PLUGIN_PATH: create the filter on ParaView sources, show every output
port as the Apply button does (pqApplyBehavior: ShowInPreferredView per port), and check what
the user then sees: the Elements coloured by cell Radiosity (magnitude), the Patches hidden,
the animation toolbar on the 10 light positions, and the last position after a step to the
end. test_gui.py runs it; the GUI shows no stderr, so the result goes to $MLR_REPORT."""
import os
import sys

sys.path.insert(0, os.environ.get("MLR_TEST_DIR") or os.path.dirname(os.path.abspath(__file__)))
import plugin_test_support as support  # noqa: E402

from paraview.simple import *  # noqa: F401,F403,E402
from paraview.modules.vtkRemotingViews import vtkSMParaViewPipelineControllerWithRendering  # noqa: E402

checks = support.Checks("Plugin.GUI")
check = checks.check


def report_and_quit():
    with open(os.environ["MLR_REPORT"], "w") as report:
        report.write("\n".join(checks.failures) + "\n" if checks.failures else "OK\n")
    sys.exit(1 if checks.failures else 0)


if not check("MovingLightRadiosity" in globals(),
             f"PV_PLUGIN_PATH={os.environ.get('PV_PLUGIN_PATH')!r} did not load the plugin"):
    report_and_quit()
support._filter = globals()["MovingLightRadiosity"]

radiosity, sources = support.box_pipeline()
view = GetActiveViewOrCreate("RenderView")
controller = vtkSMParaViewPipelineControllerWithRendering()
shown = [controller.ShowInPreferredView(radiosity.SMProxy, port, view.SMProxy) for port in (0, 1, 2)]
check(shown[0] is not None, "Apply shows no Elements")
check(shown[1] is None, "Apply shows the Patches on top of the Elements")
check(shown[2] is not None, "Apply shows no Light")
display = GetDisplayProperties(radiosity, view)
check(list(display.ColorArrayName) == ["POINTS", "Color"],
      f"the Elements are coloured by {list(display.ColorArrayName)}, expected point Color")
check(display.MapScalars == 0, "the Elements' Color goes through a colour map (Map Scalars on)")
lamp = GetDisplayProperties(OutputPort(radiosity, 2), view)
check(lamp.ColorArrayName[1] == "", f"the Light is coloured by {list(lamp.ColorArrayName)}")
Render(view)

scene = GetAnimationScene()
keeper = GetTimeKeeper()
check(list(keeper.TimestepValues) == [float(i) for i in range(support.POSITIONS)],
      f"the GUI's time keeper has {list(keeper.TimestepValues)}, expected one step per position")
scene.GoToLast()
Render(view)
frame = radiosity.GetDataInformation().DataInformation.GetFieldDataInformation() \
    .GetArrayInformation("FrameIndex")
check(frame is not None and frame.GetComponentRange(0)[0] == support.POSITIONS - 1,
      f"after Last Frame the view shows frame {frame.GetComponentRange(0) if frame else None}")
bounds = OutputPort(radiosity, 2).GetDataInformation().GetBounds()
centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2 for i in range(3)]
expected = support.light_position(support.POSITIONS - 1)
check(all(abs(a - b) < 1e-6 for a, b in zip(centre, expected)),
      f"after Last Frame the Light is centred on {centre}, expected {expected}")
report_and_quit()

"""Which MovingLightRadiosity plugin a ParaView executable loaded, and whether it runs: for
test_install.py, in pvbatch, pvpython and the paraview GUI (--script) alike, so settings come
from the environment:

  MLR_LOAD_PLUGIN   if set, LoadPlugin() this file; else the plugin must already be loaded
                    (PV_PLUGIN_PATH loads every plugin it names at start-up)
  MLR_EXPECT_PLUGIN the .so the plugin must have been loaded from
  MLR_REPORT        if set, the failures (or OK) are also written there: the GUI shows no stderr

Exits 0 when the plugin came from the expected file and solved a small scene."""
import os
import sys

# The GUI runs --script files without putting their folder on sys.path (nor __file__).
sys.path.insert(0, os.environ.get("MLR_TEST_DIR") or os.path.dirname(os.path.abspath(__file__)))
import plugin_test_support as support  # noqa: E402

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403
from paraview.modules.vtkRemotingCore import vtkPVPluginTracker

checks = support.Checks("Plugin.Loads")
check = checks.check
executable = os.path.basename(sys.executable or "") or "?"

if os.environ.get("MLR_LOAD_PLUGIN"):
    support.load_plugin(os.environ["MLR_LOAD_PLUGIN"], globals())
elif check("MovingLightRadiosity" in globals(),
           f"PV_PLUGIN_PATH={os.environ.get('PV_PLUGIN_PATH')!r} did not load the plugin at start-up"):
    support._filter = globals()["MovingLightRadiosity"]

tracker = vtkPVPluginTracker.GetInstance()
loaded = [tracker.GetPluginFileName(i) for i in range(tracker.GetNumberOfPlugins())
          if tracker.GetPluginName(i) == "MovingLightRadiosity" and tracker.GetPluginLoaded(i)]
expected = os.path.realpath(os.environ["MLR_EXPECT_PLUGIN"])
check([os.path.realpath(f) for f in loaded] == [expected],
      f"the plugin was loaded from {loaded}, expected {expected}")

if support._filter is not None:
    radiosity, _ = support.box_pipeline(NumberOfPaths=5000, PatchSize=0.2)
    radiosity.UpdatePipeline(time=2.0)
    data = servermanager.Fetch(radiosity)
    frame = data.GetFieldData().GetArray("FrameIndex")
    check(data.GetNumberOfCells() > 0 and frame is not None and frame.GetValue(0) == 2,
          "the loaded plugin did not solve the box")

if os.environ.get("MLR_REPORT"):
    with open(os.environ["MLR_REPORT"], "w") as report:
        report.write("\n".join(checks.failures) if checks.failures else "OK\n")
checks.finish()
sys.exit(0)  # the GUI stays open unless told to quit

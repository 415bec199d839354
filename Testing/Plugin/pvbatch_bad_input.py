"""One wrong input on the plugin's filter in pvbatch, then the same filter with the input
fixed. Driven by test_bad_input.py, which checks the exit code and the messages:

    pvbatch --force-offscreen-rendering pvbatch_bad_input.py CASE --plugin MovingLightRadiosity.so

CASE is `table` (a table, which has no surface, on the Scene port) or
`light-without-polygons` (a Line as the Light). Prints `MLR-BAD-INPUT cells=N` after the
failed update and `MLR-FIXED cells=N` after the fixed one."""
import sys

import plugin_test_support as support

CASES = ("table", "light-without-polygons")
args = support.parse_arguments(
    __doc__.splitlines()[0], lambda parser: parser.add_argument("case", choices=CASES))

from paraview.simple import *  # noqa: F401,F403

support.load_plugin(args.plugin, globals())

radiosity, sources = support.box_pipeline()
if args.case == "table":
    # Scripts are not held to the input domains the GUI enforces: this reaches the filter.
    radiosity.Scene = ProgrammableSource(OutputDataSetType="vtkTable")
else:
    radiosity.Light = Line()

radiosity.UpdatePipeline(time=0.0)
print(f"MLR-BAD-INPUT cells={radiosity.GetDataInformation().GetNumberOfCells()}", flush=True)

radiosity.Scene = sources["box"]
radiosity.Light = sources["light"]
radiosity.UpdatePipeline(time=0.0)
print(f"MLR-FIXED cells={radiosity.GetDataInformation().GetNumberOfCells()}", flush=True)
sys.exit(0)

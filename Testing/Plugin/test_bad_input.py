"""A wrong input gives a ParaView error message and an empty output, not a crash of pvbatch,
and the filter works again once the input is fixed. Runs pvbatch_bad_input.py in pvbatch:

    MLR_PVBATCH=pvbatch MLR_PLUGIN=.../MovingLightRadiosity.so python3 -m pytest test_bad_input.py"""
import os
import re
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
PVBATCH = os.environ.get("MLR_PVBATCH", "pvbatch")
PLUGIN = os.environ.get("MLR_PLUGIN")

# The error each case must show: the filter's own messages.
EXPECTED_ERRORS = {
    "table": r"the Scene is a vtkTable, which has no surfaces",
    "light-without-polygons": r"vtkMovingLightRadiosity.*light.* has no polygon",
}


@pytest.fixture(scope="module", autouse=True)
def plugin():
    if not PLUGIN or not os.path.isfile(PLUGIN):
        pytest.fail(f"set MLR_PLUGIN to the built MovingLightRadiosity.so (now {PLUGIN!r})")


@pytest.mark.parametrize("case", sorted(EXPECTED_ERRORS))
def test_bad_input_is_an_error_not_a_crash(case):
    run = subprocess.run(
        [PVBATCH, "--force-offscreen-rendering", os.path.join(HERE, "pvbatch_bad_input.py"), case,
         "--plugin", PLUGIN],
        capture_output=True, text=True, timeout=120)
    report = f"exit code {run.returncode}\n--- stdout\n{run.stdout}\n--- stderr\n{run.stderr}"
    assert run.returncode == 0, "pvbatch did not finish the script (a negative code is a signal):\n" + report
    assert "Traceback" not in run.stderr, report
    assert "MLR-BAD-INPUT cells=0" in run.stdout, "the bad input left a non-empty output:\n" + report
    assert re.search(r"ERR\|.*" + EXPECTED_ERRORS[case], run.stderr), \
        "no ParaView error naming the problem:\n" + report
    fixed = re.search(r"MLR-FIXED cells=(\d+)", run.stdout)
    assert fixed and int(fixed.group(1)) > 0, "the filter did not recover once the input was fixed:\n" + report


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))

"""Debian's paraview GUI loads the plugin from the build tree through PV_PLUGIN_PATH and the
Apply button shows the lit scene (gui_apply.py, run inside the GUI on a private Xvfb display)."""
import os
import shutil
import subprocess

import pytest

from xvfb_display import virtual_display

HERE = os.path.dirname(os.path.abspath(__file__))


def test_apply_in_the_gui(tmp_path):
    if not shutil.which("Xvfb"):
        pytest.skip("Xvfb is not installed")
    folder = os.environ.get("MLR_PLUGIN_DIR")
    assert folder and os.path.isdir(folder), f"set MLR_PLUGIN_DIR to the build's plugin folder ({folder!r})"
    report = tmp_path / "report.txt"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(PV_PLUGIN_PATH=folder, MLR_REPORT=str(report), MLR_TEST_DIR=HERE)
    # --dr: no user settings read or written (plugins remembered from earlier sessions).
    with virtual_display() as display:
        run = subprocess.run([os.environ.get("MLR_PARAVIEW", "paraview"), "--dr",
                              f"--script={os.path.join(HERE, 'gui_apply.py')}"],
                             capture_output=True, text=True, timeout=180, env=dict(env, DISPLAY=display))
    text = report.read_text() if report.exists() else "(no report: the script did not run)"
    assert run.returncode == 0 and text.strip() == "OK", \
        f"{text}\nexit code {run.returncode}\n--- stdout\n{run.stdout}\n--- stderr\n{run.stderr}"

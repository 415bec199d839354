"""mlr-benchmark's accuracy cases (ends, error-bars, target-error) at a small size: each runs
and writes JSON whose figures are finite. Figures at full size are in
Documentation/Performance.md; none is asserted here.
"""
import json
import math
import os
import subprocess

import pytest


def solve(tmp_path, case, *extra):
    out = tmp_path / (case + ".json")
    result = subprocess.run(
        [os.environ["MLR_BENCHMARK"], "--case", case, "--paths", "3000", "--frames", "4",
         "--reference-factor", "2", "--cache", "", "--json", str(out), *extra],
        capture_output=True, text=True, timeout=280)
    assert result.returncode == 0, result.stderr
    with open(out) as f:
        return json.load(f), result.stdout


def test_ends(tmp_path):
    data, text = solve(tmp_path, "ends")
    # --frames 4 clamps the lights' windows to the animation; the sun keeps its 48 frames.
    for case, width in (("paper_room", 4), ("turning_light", 4), ("sun_over_town", 12)):
        schemes = data["ends"][case]["schemes"]
        assert [s["name"].split(",")[0] for s in schemes][:3] == \
            ["classic", "full reuse", "full reuse"]
        for scheme in schemes:
            assert all(math.isfinite(r) and r > 0 for r in scheme["mse_ratio"]), scheme["name"]
        centred = [s for s in schemes if s["name"] == f"centred windows of {width} (time from rays)"]
        assert len(centred) == 1
        # Its time is estimated from the rays: finite, positive.
        assert math.isfinite(centred[0]["cpu_seconds"]) and centred[0]["cpu_seconds"] > 0
        assert math.isfinite(centred[0]["seconds"]) and centred[0]["seconds"] > 0
        windows = data["ends"][case]["first_hit_factor_windows"]
        assert [w["shares"] for w in windows] == [f"runs of {width} positions",
                                                  f"centred windows of {width} positions"]
        assert all(math.isfinite(w["worst"]) and w["worst"] > 0 for w in windows)
    assert "First-hit variance factor" in text


def test_error_bars(tmp_path):
    data, _ = solve(tmp_path, "error-bars", "--seeds", "3")
    frames = data["error_bars"]["per_frame"]
    assert len(frames) == 4
    for f in frames:
        assert math.isfinite(f["ratio"]) and 0 <= f["coverage"] <= 1


def test_target_error(tmp_path):
    data, _ = solve(tmp_path, "target-error", "--target-error", "0.5")
    t = data["target_error"]
    assert t["stopped_by"] == "target"
    assert t["paths_per_frame"] >= 3000
    assert math.isfinite(t["achieved_p95"])
